// SPDX-License-Identifier: Apache-2.0
#pragma once
// Back-pressure between acquisition and processing: a bounded queue where, when full, the newest wins.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

namespace cellmap::daemon {

/// Holds at most `capacity` items, handed out oldest first. put() on a full mailbox drops the oldest item and
/// counts it as dropped, so a consumer stalled for a while (the first segmentation of a cell takes seconds)
/// loses nothing it can catch up on, one that stays too slow gets the newest items, and memory never grows
/// beyond `capacity` items. Thread-safe for any number of producers and consumers.
template <typename T>
class BoundedMailbox {
 public:
  /// `capacity` ≥ 1 (0 is taken as 1): with 1, put() replaces any item not yet taken.
  explicit BoundedMailbox(std::size_t capacity = 1) : capacity_(capacity > 0 ? capacity : 1) {}

  /// Appends `item`, dropping (and counting) the oldest item when `capacity` wait; wakes one waiting take().
  /// Returns the item it dropped, if any (for the caller to count what it held).
  std::optional<T> put(T item) {
    std::optional<T> dropped;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (items_.size() >= capacity_) {
        dropped = std::move(items_.front());
        items_.pop_front();
        ++dropped_;
      }
      items_.push_back(std::move(item));
    }
    ready_.notify_one();
    return dropped;
  }

  /// Waits up to `timeout` for an item and takes the oldest; empty on timeout, or after close() when none is
  /// left.
  [[nodiscard]] std::optional<T> take(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, timeout, [&] { return !items_.empty() || closed_; });
    std::optional<T> out;
    if (!items_.empty()) {
      out = std::move(items_.front());
      items_.pop_front();
    }
    lock.unlock();
    taken_.notify_all();
    return out;
  }

  /// Waits up to `timeout` until put() would drop nothing (fewer than `capacity` items wait); true when so.
  /// Lets a producer that must not lose items (a replay played as fast as processed) wait instead.
  [[nodiscard]] bool wait_for_room(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return taken_.wait_for(lock, timeout, [&] { return items_.size() < capacity_; });
  }

  /// Wakes every waiting take(); later takes return at once with what is left.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  /// How many items were dropped before anyone took them.
  [[nodiscard]] std::uint64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::condition_variable taken_;
  std::deque<T> items_;
  std::uint64_t dropped_ = 0;
  bool closed_ = false;
};

}  // namespace cellmap::daemon
