// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sensor/depth_source.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <sstream>

#include "cellmap/common/error.hpp"

namespace cellmap {

std::string DepthMode::to_string() const {
  std::ostringstream text;
  text << width << "x" << height << "@" << fps << " " << format;
  return text.str();
}

std::string describe_modes(const std::vector<DepthMode>& modes) {
  if (modes.empty()) return "nothing";
  std::string text;
  for (const DepthMode& mode : modes) text += (text.empty() ? "" : ", ") + mode.to_string();
  return text;
}

DepthMode choose_depth_mode(const std::vector<DepthMode>& offered, const DepthMode& wanted,
                            const std::string& device) {
  const DepthMode* best = nullptr;
  for (const DepthMode& mode : offered) {
    if (mode.format != wanted.format || mode.width != wanted.width || mode.height != wanted.height) continue;
    if (wanted.fps > 0) {
      // Drivers report rates as fractions (30000/1001); half a frame per second tells 30 from 25 or 60.
      if (std::abs(mode.fps - wanted.fps) <= 0.5 &&
          (!best || std::abs(mode.fps - wanted.fps) < std::abs(best->fps - wanted.fps))) {
        best = &mode;
      }
    } else if (!best || mode.fps > best->fps) {
      best = &mode;
    }
  }
  if (!best) {
    throw Error(device + ": no mode " + wanted.to_string() + (wanted.fps > 0 ? "" : " (any rate)") +
                "; offers " + describe_modes(offered));
  }
  return *best;
}

const char* to_string(SourceState state) {
  switch (state) {
    case SourceState::kClosed:
      return "closed";
    case SourceState::kConnected:
      return "connected";
    case SourceState::kDisconnected:
      return "disconnected";
    case SourceState::kError:
      return "error";
    case SourceState::kEnded:
      return "ended";
  }
  return "unknown";
}

double DeviceClock::to_host(std::uint64_t device_us, double host_seconds) {
  const double offset = host_seconds - static_cast<double>(device_us) * 1e-6;
  if (!have_offset_ || offset < offset_) {
    offset_ = offset;
    have_offset_ = true;
  }
  return static_cast<double>(device_us) * 1e-6 + offset_;
}

double realtime_seconds() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<double>(now.tv_sec) + static_cast<double>(now.tv_nsec) * 1e-9;
}

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace cellmap
