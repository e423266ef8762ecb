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

LogBudget::LogBudget(std::size_t lines, Clock::duration interval) : lines_(lines), interval_(interval) {}

std::optional<std::string> LogBudget::admit(const std::string& line, Clock::time_point now) {
  if (!window_start_ || now - *window_start_ >= interval_) {
    window_start_ = now;
    in_window_ = 0;
  }
  if (in_window_ >= lines_) {
    ++held_back_;
    return std::nullopt;
  }
  ++in_window_;
  if (held_back_ == 0) return line;
  const std::string admitted = line + " (" + std::to_string(held_back_) + " more not logged)";
  held_back_ = 0;
  return admitted;
}

}  // namespace cellmap::daemon
