// SPDX-License-Identifier: Apache-2.0
#pragma once
// The wall clock as cellmap's messages stamp it.

#include <chrono>
#include <cstdint>

namespace cellmap {

/// Now, in ns since the Unix epoch (std::chrono::system_clock: may step when the host's clock is set, so
/// intervals are measured with std::chrono::steady_clock instead). Thread safe.
[[nodiscard]] inline std::int64_t wall_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace cellmap
