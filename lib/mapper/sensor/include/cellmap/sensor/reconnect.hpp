// SPDX-License-Identifier: Apache-2.0
#pragma once
// When a camera source should try to (re)connect: a small state machine driven by a clock the caller passes
// in.

#include <chrono>
#include <functional>
#include <string>

#include "cellmap/common/steady_clock.hpp"
#include "cellmap/sensor/depth_source.hpp"

namespace cellmap {

/// Timings of the reconnect state machine, seconds.
struct ReconnectParams final {
  double frame_timeout = 2.0;    ///< connected but no frame for this long → disconnected
  double initial_backoff = 0.5;  ///< wait before the first retry
  double max_backoff = 10.0;     ///< the wait doubles after each failed attempt, up to this
  double factor = 2.0;           ///< growth of the wait per failed attempt

  /// @throws Error if a time is not positive, max_backoff < initial_backoff, or factor < 1.
  void validate() const;
};

/// Connection state machine of one source. Times are seconds on the source's steady clock (seconds since its
/// epoch), given by the caller, so the logic is tested without sleeping; only retry_or_wait() reads the clock
/// and sleeps on it. Transitions:
///   closed/disconnected --connected()--> connected --frame()--> connected (back-off reset to initial)
///   connected --lost() or check() after frame_timeout without frames--> disconnected (retry at now +
///   back-off) any --failed()--> error (no retries) ; any --closed()--> closed
/// The back-off resets only when a frame arrives, so a device that opens but never streams backs off too.
/// Not thread-safe.
class Reconnector final {
 public:
  /// `clock` (which must outlive the reconnector) is what retry_or_wait() reads and sleeps on.
  /// @throws Error if the policy is invalid.
  explicit Reconnector(const ReconnectParams& policy = {}, SteadyClock& clock = SteadyClock::real());

  /// An open succeeded at `now`; the frame timeout starts counting.
  void connected(double now);
  /// A frame arrived at `now`.
  void frame(double now);
  /// An open failed or the device went away at `now`: disconnected, next attempt after the current back-off,
  /// which then grows.
  void lost(double now, const std::string& reason);
  /// A fault retrying cannot fix.
  void failed(const std::string& reason);
  void closed();

  /// If connected and silent for frame_timeout at `now`, turns disconnected ("no frames for T s") and returns
  /// true.
  bool check(double now);
  /// True when disconnected and the next attempt is due at `now`.
  [[nodiscard]] bool retry_due(double now) const;
  /// What a source's next() does while disconnected: calls `connect(now)` (which reports connected() or
  /// lost()) if the attempt is due now on the clock (for the real one: steady_seconds()), else sleeps on it
  /// until the attempt is due or `timeout` passed, whichever comes first, so callers never spin.
  void retry_or_wait(std::chrono::milliseconds timeout, const std::function<void(double now)>& connect);

  [[nodiscard]] SourceState state() const { return state_; }
  [[nodiscard]] const std::string& reason() const { return reason_; }
  /// Time of the next attempt (meaningful while disconnected).
  [[nodiscard]] double next_attempt() const { return next_attempt_; }
  /// The wait that the next failure will schedule.
  [[nodiscard]] double backoff() const { return backoff_; }
  [[nodiscard]] const ReconnectParams& policy() const { return policy_; }

 private:
  ReconnectParams policy_;
  SteadyClock* clock_;  // never null
  SourceState state_ = SourceState::kClosed;
  std::string reason_;
  double last_frame_ = 0.0;
  double next_attempt_ = 0.0;
  double backoff_ = 0.0;
};

}  // namespace cellmap
