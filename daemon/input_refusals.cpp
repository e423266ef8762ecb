// SPDX-License-Identifier: Apache-2.0
#include "input_refusals.hpp"

namespace cellmap::daemon {

InputRefusals::InputRefusals(Log log, Clock::duration interval) : log_(std::move(log)), interval_(interval) {}

void InputRefusals::refuse(const std::string& reason, Clock::time_point now) {
  const std::uint64_t total = ++count_;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (last_line_ && now - *last_line_ < interval_) return;
    last_line_ = now;
  }
  log_("refused: " + reason + " (" + std::to_string(total) + " inputs refused so far)");
}

}  // namespace cellmap::daemon
