// SPDX-License-Identifier: Apache-2.0
#pragma once
// sensor_msgs/msg/LaserScan → points: what a 2D lidar's ROS 2 driver publishes (the paper's OS32C, swept
// by the gantry, among them). Frame: the scanner's, beams in its x–y plane, angles about +z from +x (as
// cellmap's simulated line scanner and ROS's REP 103 and 117 have it).

#include <cstddef>
#include <cstdint>

#include "cellmap/common/field_of_view.hpp"
#include "cellmap/frame/cloud.hpp"

namespace cellmap::ros2 {

/// A received sensor_msgs/msg/LaserScan with its ranges borrowed (not owned): valid while the sample is.
struct LaserScanView final {
  float angle_min = 0.0f;        ///< radians, of the first beam
  float angle_max = 0.0f;        ///< radians, of the last beam
  float angle_increment = 0.0f;  ///< radians from one beam to the next (negative: clockwise)
  float range_min = 0.0f;        ///< metres
  float range_max = 0.0f;        ///< metres
  const float* ranges = nullptr;
  std::size_t count = 0;
};

/// The largest scan accepted, beams (2D lidars send 0.5–10 k).
inline constexpr std::size_t kMaxScanBeams = 1'000'000;
/// The longest range accepted, metres: no scanner reaches farther, and a robot cell is far smaller.
inline constexpr float kMaxScanRange = 1000.0f;

/// What one scan says, in the scanner frame S.
struct ScanPoints final {
  Cloud points_S;  ///< one point per beam whose range lies in [range_min, range_max]
  /// The far end (at range_max) of each beam that reported nothing within range (+inf, or above
  /// range_max): the scanner looked along it and saw no surface that near (REP 117). NaN, -inf and ranges
  /// below range_min say nothing and are left out of both.
  Cloud no_return_S;
  FieldOfView fan;  ///< the beams' fan: rays at most 30° apart from the first beam to the last
};

/// The returns of `scan`: beam i at angle_min + i · angle_increment. Pure function; thread-safe.
/// @throws Error with one line saying what is wrong: a non-finite angle or range limit, angle_increment 0,
/// range_min negative or not below range_max, range_max over kMaxScanRange, more than kMaxScanBeams beams,
/// or a beam count that does not match (angle_max − angle_min) / angle_increment + 1 within one beam.
[[nodiscard]] ScanPoints to_points(const LaserScanView& scan);

}  // namespace cellmap::ros2
