// SPDX-License-Identifier: Apache-2.0
// sensor_msgs/msg/LaserScan → points with known answers (REP 117's meanings of inf and NaN), the fan, and
// every malformed kind refused.
#include "cellmap/ros2/laser_scan.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "cellmap/common/error.hpp"

namespace cellmap::ros2 {
namespace {

using ::testing::HasSubstr;

constexpr float kPi = 3.14159265358979f;
constexpr float kNoReturn = std::numeric_limits<float>::infinity();
constexpr float kNoMeasurement = std::numeric_limits<float>::quiet_NaN();

LaserScanView scan_of(const std::vector<float>& ranges, float angle_min, float increment) {
  LaserScanView scan;
  scan.angle_min = angle_min;
  scan.angle_increment = increment;
  scan.angle_max = angle_min + increment * float(ranges.size() - 1);
  scan.range_min = 0.1f;
  scan.range_max = 4.0f;
  scan.ranges = ranges.data();
  scan.count = ranges.size();
  return scan;
}

std::string refusal(const LaserScanView& scan) {
  try {
    (void)to_points(scan);
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

// Five beams from −90° to +90°: a return, nothing in range (+inf), no measurement (NaN), too near, beyond
// range_max (nothing within range too).
TEST(LaserScanTest, ReturnsAndBeamsWithoutReturnInTheScannersPlane) {
  const std::vector<float> ranges{1.0f, kNoReturn, kNoMeasurement, 0.05f, 6.0f};
  const ScanPoints out = to_points(scan_of(ranges, -kPi / 2, kPi / 4));
  ASSERT_EQ(out.points_S.size(), 1u);
  EXPECT_NEAR(out.points_S[0].x, 0.0, 1e-6);
  EXPECT_NEAR(out.points_S[0].y, -1.0, 1e-6);
  EXPECT_EQ(out.points_S[0].z, 0.0f);
  ASSERT_EQ(out.no_return_S.size(), 2u);
  EXPECT_NEAR(out.no_return_S[0].x, 4.0 * std::cos(-kPi / 4), 1e-5);  // −45° at range_max
  EXPECT_NEAR(out.no_return_S[0].y, 4.0 * std::sin(-kPi / 4), 1e-5);
  EXPECT_NEAR(out.no_return_S[1].x, 0.0, 1e-5);  // +90° at range_max, not at 6 m
  EXPECT_NEAR(out.no_return_S[1].y, 4.0, 1e-5);
}

TEST(LaserScanTest, ClockwiseScansAndTheirFan) {
  const std::vector<float> ranges{2.0f, 2.0f, 2.0f};
  const ScanPoints out = to_points(scan_of(ranges, kPi / 2, -kPi / 2));  // +90°, 0°, −90°
  ASSERT_EQ(out.points_S.size(), 3u);
  EXPECT_NEAR(out.points_S[0].y, 2.0, 1e-5);
  EXPECT_NEAR(out.points_S[1].x, 2.0, 1e-5);
  EXPECT_NEAR(out.points_S[2].y, -2.0, 1e-5);
  // 180° in rays at most 30° apart: 6 gaps, from the first beam to the last.
  ASSERT_EQ(out.fan.outline_S.size(), 7u);
  EXPECT_NEAR(out.fan.outline_S.front().y(), 1.0, 1e-6);
  EXPECT_NEAR(out.fan.outline_S.back().y(), -1.0, 1e-6);
  EXPECT_FALSE(out.fan.closed);
  EXPECT_EQ(out.fan.max_range, 4.0);
}

TEST(LaserScanTest, MalformedScansAreRefusedWithTheirReason) {
  const std::vector<float> ranges{1.0f, 1.0f, 1.0f};
  LaserScanView scan = scan_of(ranges, 0.0f, 0.1f);
  EXPECT_EQ(refusal(scan), "accepted");

  LaserScanView zero = scan;
  zero.angle_increment = 0.0f;
  EXPECT_EQ(refusal(zero), "angle_increment is 0");

  LaserScanView nan_angle = scan;
  nan_angle.angle_min = kNoMeasurement;
  EXPECT_THAT(refusal(nan_angle), HasSubstr("must be finite"));

  LaserScanView inverted = scan;
  inverted.range_min = 5.0f;
  EXPECT_THAT(refusal(inverted), HasSubstr("below range_max"));

  LaserScanView absurd = scan;
  absurd.range_max = 1e9f;
  EXPECT_THAT(refusal(absurd), HasSubstr("is absurd"));

  LaserScanView too_few = scan;
  too_few.angle_max = 1.0f;  // 11 beams' worth of angles for 3 ranges
  EXPECT_THAT(refusal(too_few), HasSubstr("3 ranges for angles"));

  LaserScanView empty = scan;
  empty.count = 0;
  EXPECT_THAT(refusal(empty), HasSubstr("0 ranges"));

  LaserScanView wrapping = scan;  // 3 beams 4 rad apart: more than a turn
  wrapping.angle_increment = 4.0f;
  wrapping.angle_max = 8.0f;
  EXPECT_THAT(refusal(wrapping), HasSubstr("3 ranges for angles"));
}

}  // namespace
}  // namespace cellmap::ros2
