// SPDX-License-Identifier: Apache-2.0
#pragma once
// On a machine with few cores, the version a closed sweep makes would wait for the CPU that gathering the
// next sweep's frames takes meanwhile. Those frames are not needed before their own sweep closes, a sweep
// period later, so while a closed sweep is processed they wait in the frame queue: its version goes out
// first.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>

namespace cellmap::daemon {

/// Thread-safe: one processing thread takes turns, any thread waits.
class ClosedSweepFirst final {
 public:
  /// The processing of one closed sweep, from construction until destruction, on the processing thread.
  class Turn final {
   public:
    explicit Turn(ClosedSweepFirst& gate) : gate_(gate) { gate_.set_busy(true); }
    ~Turn() { gate_.set_busy(false); }
    Turn(const Turn&) = delete;
    Turn& operator=(const Turn&) = delete;

   private:
    ClosedSweepFirst& gate_;
  };

  /// Returns once no closed sweep is being processed, or `waiting()` frames reach `backlog` (more waiting
  /// would soon drop frames: they are gathered then, side by side with the processing), or `stop` is set.
  /// The last two are checked every `poll`; the end of a turn wakes the waiter at once.
  template <class Waiting>
  void wait(const Waiting& waiting, std::size_t backlog, const std::atomic<bool>& stop,
            std::chrono::milliseconds poll = std::chrono::milliseconds(2)) {
    std::unique_lock<std::mutex> lock(mutex_);
    while (busy_ && waiting() < backlog && !stop) idle_.wait_for(lock, poll);
  }

 private:
  void set_busy(bool busy) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      busy_ = busy;
    }
    if (!busy) idle_.notify_all();
  }

  std::mutex mutex_;
  std::condition_variable idle_;
  bool busy_ = false;
};

}  // namespace cellmap::daemon
