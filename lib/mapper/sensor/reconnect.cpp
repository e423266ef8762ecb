// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sensor/reconnect.hpp"

#include <algorithm>
#include <sstream>

#include "cellmap/common/error.hpp"

namespace cellmap {

void ReconnectParams::validate() const {
  if (!(frame_timeout > 0)) throw Error("reconnect: frame_timeout must be > 0");
  if (!(initial_backoff > 0)) throw Error("reconnect: initial_backoff must be > 0");
  if (!(max_backoff >= initial_backoff)) throw Error("reconnect: max_backoff must be >= initial_backoff");
  if (!(factor >= 1.0)) throw Error("reconnect: factor must be >= 1");
}

Reconnector::Reconnector(const ReconnectParams& policy, SteadyClock& clock)
    : policy_(policy), clock_(&clock), backoff_(policy.initial_backoff) {
  policy_.validate();
}

void Reconnector::connected(double now) {
  state_ = SourceState::kConnected;
  reason_.clear();
  last_frame_ = now;
}

void Reconnector::frame(double now) {
  last_frame_ = now;
  backoff_ = policy_.initial_backoff;
}

void Reconnector::lost(double now, const std::string& reason) {
  state_ = SourceState::kDisconnected;
  reason_ = reason;
  next_attempt_ = now + backoff_;
  backoff_ = std::min(backoff_ * policy_.factor, policy_.max_backoff);
}

void Reconnector::failed(const std::string& reason) {
  state_ = SourceState::kError;
  reason_ = reason;
}

void Reconnector::closed() {
  state_ = SourceState::kClosed;
  reason_.clear();
  backoff_ = policy_.initial_backoff;
}

bool Reconnector::check(double now) {
  if (state_ != SourceState::kConnected || now - last_frame_ < policy_.frame_timeout) return false;
  std::ostringstream reason;
  reason << "no frames for " << policy_.frame_timeout << " s";
  lost(now, reason.str());
  return true;
}

bool Reconnector::retry_due(double now) const {
  return state_ == SourceState::kDisconnected && now >= next_attempt_;
}

void Reconnector::retry_or_wait(std::chrono::milliseconds timeout,
                                const std::function<void(double now)>& connect) {
  const double now = std::chrono::duration<double>(clock_->now().time_since_epoch()).count();
  if (retry_due(now)) {
    connect(now);
    return;
  }
  const double wait = std::min(next_attempt_ - now, static_cast<double>(timeout.count()) * 1e-3);
  // Rounded up: a sleep that ends a nanosecond before the attempt is due would cost the caller a second call.
  clock_->sleep_for(
      std::chrono::ceil<SteadyClock::duration>(std::chrono::duration<double>(std::max(wait, 0.0))));
}

}  // namespace cellmap
