#pragma once
// Back-pressure between acquisition and processing: a one-slot mailbox where the newest item wins.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <utility>

namespace cellmap::daemon {

/// Holds at most one item. put() replaces an item nobody has taken yet and counts it as dropped, so a slow
/// consumer always gets the newest sweep and memory never grows with the backlog. Thread-safe for any number
/// of producers and consumers.
template <typename T>
class LatestMailbox {
 public:
  /// Stores `item`, replacing (and counting as dropped) any item not yet taken; wakes one waiting take().
  void put(T item) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (slot_) ++dropped_;
      slot_ = std::move(item);
    }
    ready_.notify_one();
  }

  /// Waits up to `timeout` for an item and takes it; empty on timeout or after close().
  [[nodiscard]] std::optional<T> take(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, timeout, [&] { return slot_.has_value() || closed_; });
    std::optional<T> out = std::move(slot_);
    slot_.reset();
    lock.unlock();
    taken_.notify_all();
    return out;
  }

  /// Waits up to `timeout` until the slot is empty (the consumer took the last item); true when it is. Lets
  /// a producer that must not lose items (a replay played as fast as processed) wait instead of replacing.
  [[nodiscard]] bool wait_taken(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return taken_.wait_for(lock, timeout, [&] { return !slot_.has_value(); });
  }

  /// Wakes every waiting take(); later takes return at once with what is left.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  /// How many items were replaced before anyone took them.
  [[nodiscard]] std::uint64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::condition_variable taken_;
  std::optional<T> slot_;
  std::uint64_t dropped_ = 0;
  bool closed_ = false;
};

}  // namespace cellmap::daemon
