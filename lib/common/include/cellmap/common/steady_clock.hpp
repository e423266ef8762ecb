// SPDX-License-Identifier: Apache-2.0
#pragma once
// The monotonic clock that code which waits for a time reads and sleeps on, so a test can drive it.

#include <chrono>
#include <thread>

namespace cellmap {

/// A monotonic clock that also puts the calling thread to sleep. Code that waits for an instant (a replay
/// playing frames at their recorded times, a source backing off before it reconnects) takes one, so a test
/// can pass a clock it drives and check what happens when, whatever the machine's load. In production it is
/// SteadyClock::real(): std::chrono::steady_clock and std::this_thread.
class SteadyClock {
 public:
  using time_point = std::chrono::steady_clock::time_point;
  using duration = std::chrono::steady_clock::duration;

  SteadyClock() = default;
  SteadyClock(const SteadyClock&) = delete;
  SteadyClock& operator=(const SteadyClock&) = delete;
  virtual ~SteadyClock() = default;

  /// The current instant. Thread safe.
  [[nodiscard]] virtual time_point now() const = 0;
  /// Returns once now() has reached `when`; at once if it has. Thread safe.
  virtual void sleep_until(time_point when) = 0;
  /// sleep_until(now() + how_long).
  void sleep_for(duration how_long) { sleep_until(now() + how_long); }

  /// std::chrono::steady_clock, slept on with std::this_thread; lives as long as the program.
  [[nodiscard]] static SteadyClock& real();
};

namespace detail {
class RealSteadyClock final : public SteadyClock {
 public:
  [[nodiscard]] time_point now() const override { return std::chrono::steady_clock::now(); }
  void sleep_until(time_point when) override { std::this_thread::sleep_until(when); }
};
}  // namespace detail

inline SteadyClock& SteadyClock::real() {
  static detail::RealSteadyClock clock;
  return clock;
}

}  // namespace cellmap
