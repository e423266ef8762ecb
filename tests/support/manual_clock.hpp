// SPDX-License-Identifier: Apache-2.0
#pragma once
// A clock the test drives, for code that takes a SteadyClock: what it does at which instant is then checked
// exactly, and a loaded machine (or a sanitizer) cannot move the instants.

#include <algorithm>
#include <chrono>
#include <mutex>

#include "cellmap/common/steady_clock.hpp"

namespace cellmap::test {

/// A SteadyClock whose time moves only when code sleeps on it (sleep_until jumps to the instant at once) or
/// the test calls advance(). Thread safe.
class ManualClock final : public SteadyClock {
 public:
  /// Starts at 1000 s on the clock (any instant would do; not zero, so "no time" is not mistaken for it).
  ManualClock() : now_(std::chrono::seconds(1000)) {}

  [[nodiscard]] time_point now() const override {
    const std::lock_guard<std::mutex> lock(mutex_);
    return now_;
  }
  void sleep_until(time_point when) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    now_ = std::max(now_, when);
  }
  void advance(duration how_long) {
    const std::lock_guard<std::mutex> lock(mutex_);
    now_ += how_long;
  }

 private:
  mutable std::mutex mutex_;
  time_point now_;
};

}  // namespace cellmap::test
