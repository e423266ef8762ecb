// SPDX-License-Identifier: Apache-2.0
#pragma once
// How lib/ros2 quotes text from the network in its refusals: internal.

#include <string>

#include "cellmap/common/text.hpp"
#include "cellmap/transport/input_limits.hpp"

namespace cellmap::ros2 {

/// `text` in single quotes, on one line, cut at kMaxNameLength bytes: a refusal stays one short line.
[[nodiscard]] inline std::string quoted(const std::string& text) {
  return "'" + single_line(text.substr(0, transport::kMaxNameLength)) + "'";
}

}  // namespace cellmap::ros2
