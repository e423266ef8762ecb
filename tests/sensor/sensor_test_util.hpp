// SPDX-License-Identifier: Apache-2.0
#pragma once
// Helpers shared by the sensor tests: files in a temporary folder, fast reconnect timings, a synthetic depth
// image.

#include <string>

#include "cellmap/sensor/depth_io.hpp"
#include "cellmap/sensor/reconnect.hpp"
#include "support/test_support.hpp"

namespace cellmap::test {

/// dir / "name": a file in a test folder, as the string the sensor API takes.
inline std::string operator/(const TempDir& dir, const std::string& name) {
  return (dir.path() / name).string();
}

/// Reconnect timings short enough for tests: 20 ms first back-off, 100 ms cap, 0.5 s frame timeout.
inline ReconnectParams fast_retries() {
  ReconnectParams policy;
  policy.initial_backoff = 0.02;
  policy.max_backoff = 0.1;
  policy.frame_timeout = 0.5;
  return policy;
}

/// width × height raw depth: column 0 without returns, elsewhere 1000 + 300 v + u.
inline RawDepth ramp(int width, int height) {
  RawDepth image;
  image.width = width;
  image.height = height;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u)
      image.depth.push_back(static_cast<std::uint16_t>(u == 0 ? 0 : 1000 + 300 * v + u));
  }
  return image;
}

}  // namespace cellmap::test
