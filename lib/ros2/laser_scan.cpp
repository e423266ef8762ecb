// SPDX-License-Identifier: Apache-2.0
#include "cellmap/ros2/laser_scan.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap::ros2 {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMaxFanGap = 30.0 * kPi / 180.0;

void check(const LaserScanView& scan) {
  for (const float value :
       {scan.angle_min, scan.angle_max, scan.angle_increment, scan.range_min, scan.range_max}) {
    if (!std::isfinite(value)) throw Error("angles and range limits must be finite");
  }
  if (scan.angle_increment == 0.0f) throw Error("angle_increment is 0");
  if (scan.range_min < 0.0f || scan.range_min >= scan.range_max) {
    throw Error("range_min " + std::to_string(scan.range_min) + " must be >= 0 and below range_max " +
                std::to_string(scan.range_max));
  }
  if (scan.range_max > kMaxScanRange)
    throw Error("range_max " + std::to_string(scan.range_max) + " m is absurd");
  if (scan.count > kMaxScanBeams)
    throw Error(std::to_string(scan.count) + " beams, more than " + std::to_string(kMaxScanBeams));
  // Drivers round the last angle differently: allow a beam either way, never a scan that would wrap.
  const double spanned = (double(scan.angle_max) - scan.angle_min) / scan.angle_increment + 1.0;
  if (scan.count == 0 || std::abs(spanned - double(scan.count)) > 1.0 + 1e-6 ||
      std::abs(double(scan.angle_increment)) * double(scan.count - 1) > 2.0 * kPi + 1e-6) {
    throw Error(std::to_string(scan.count) + " ranges for angles " + std::to_string(scan.angle_min) + " to " +
                std::to_string(scan.angle_max) + " by " + std::to_string(scan.angle_increment));
  }
}

Eigen::Vector3d beam(double angle) {
  return {std::cos(angle), std::sin(angle), 0.0};
}

FieldOfView fan_of(const LaserScanView& scan) {
  FieldOfView fan;
  fan.max_range = scan.range_max;
  const double first = scan.angle_min;
  const double span = double(scan.angle_increment) * double(scan.count - 1);
  const int gaps = std::max(1, static_cast<int>(std::ceil(std::abs(span) / kMaxFanGap - 1e-6)));
  for (int i = 0; i <= gaps; ++i) fan.outline_S.push_back(beam(first + span * i / gaps));
  return fan;
}

}  // namespace

ScanPoints to_points(const LaserScanView& scan) {
  check(scan);
  ScanPoints out;
  out.fan = fan_of(scan);
  for (std::size_t i = 0; i < scan.count; ++i) {
    const float range = scan.ranges[i];
    if (std::isnan(range) || range < scan.range_min) continue;
    const double angle = double(scan.angle_min) + double(i) * scan.angle_increment;
    const bool returned = range <= scan.range_max;
    const Eigen::Vector3d p = beam(angle) * (returned ? double(range) : double(scan.range_max));
    (returned ? out.points_S : out.no_return_S).push_back(pcl::PointXYZ(float(p.x()), float(p.y()), 0.0f));
  }
  set_unorganized(out.points_S);
  set_unorganized(out.no_return_S);
  return out;
}

}  // namespace cellmap::ros2
