// SPDX-License-Identifier: Apache-2.0
#pragma once
// Frames on their way from the acquisition to the thread that gathers them into sweeps, with the ends of the
// sweeps between them.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

#include "cellmap/cell/open_sweep.hpp"

namespace cellmap::daemon {

/// A posed frame, or the end of the open sweep (no frame).
struct FrameItem {
  std::optional<SweepFrame> frame;
};

/// Holds at most `capacity` frames, handed out oldest first, and the sweep ends between them. put() on a
/// full queue drops the oldest waiting frame and counts it, so memory stays bounded and a consumer that
/// stays too slow gets the newest frames; an end of sweep is never dropped (it holds no memory), so sweeps
/// stay apart whatever was dropped: one whose every frame was dropped ends with nothing in it. Thread-safe
/// for any number of producers and consumers.
class FrameQueue {
 public:
  /// `capacity` ≥ 1 frames (0 is taken as 1).
  explicit FrameQueue(std::size_t capacity = 1) : capacity_(capacity > 0 ? capacity : 1) {}

  /// Appends `frame`, dropping (and counting) the oldest waiting frame when `capacity` wait.
  void put(SweepFrame frame) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (frames_ >= capacity_) drop_oldest_frame();
      items_.push_back({std::move(frame)});
      ++frames_;
    }
    ready_.notify_one();
  }

  /// Appends the end of the open sweep (a second end in a row adds nothing: no sweep lies between).
  void end_sweep() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!items_.empty() && !items_.back().frame) return;
      items_.push_back({});
    }
    ready_.notify_one();
  }

  /// Waits up to `timeout` for an item and takes the oldest; empty on timeout, or after close() when none
  /// is left.
  [[nodiscard]] std::optional<FrameItem> take(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, timeout, [&] { return !items_.empty() || closed_; });
    std::optional<FrameItem> out;
    if (!items_.empty()) {
      out = std::move(items_.front());
      items_.pop_front();
      if (out->frame) --frames_;
    }
    lock.unlock();
    taken_.notify_all();
    return out;
  }

  /// Waits up to `timeout` until put() would drop nothing; true when so. Lets a producer that must not lose
  /// frames (a replay played as fast as processed) wait instead.
  [[nodiscard]] bool wait_for_room(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return taken_.wait_for(lock, timeout, [&] { return frames_ < capacity_; });
  }

  /// Wakes every waiting take(); later takes return at once with what is left.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  /// Frames waiting to be taken.
  [[nodiscard]] std::size_t waiting() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_;
  }

  /// How many frames were dropped before anyone took them.
  [[nodiscard]] std::uint64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }

 private:
  void drop_oldest_frame() {
    for (auto it = items_.begin(); it != items_.end(); ++it) {
      if (!it->frame) continue;
      items_.erase(it);
      --frames_;
      ++dropped_;
      return;
    }
  }

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::condition_variable taken_;
  std::deque<FrameItem> items_;
  std::size_t frames_ = 0;  // items holding a frame
  std::uint64_t dropped_ = 0;
  bool closed_ = false;
};

}  // namespace cellmap::daemon
