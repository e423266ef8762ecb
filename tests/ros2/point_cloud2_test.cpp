// SPDX-License-Identifier: Apache-2.0
// sensor_msgs/msg/PointCloud2 layouts as ROS 2 drivers send them, read for x, y, z with known answers, and
// every malformed kind refused with its reason.
#include "cellmap/ros2/point_cloud2.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "cellmap/common/error.hpp"

namespace cellmap::ros2 {
namespace {

using ::testing::HasSubstr;

constexpr auto kFloat32 = static_cast<std::uint8_t>(PointFieldType::kFloat32);
constexpr auto kFloat64 = static_cast<std::uint8_t>(PointFieldType::kFloat64);
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A cloud whose bytes it owns; `view()` borrows them as a received sample would.
struct OwnedCloud {
  PointCloud2View header;
  std::vector<std::uint8_t> data;

  [[nodiscard]] PointCloud2View view() const {
    PointCloud2View v = header;
    v.data = data.data();
    v.data_size = data.size();
    return v;
  }
  template <typename T>
  void put(std::size_t at, T value) {
    std::memcpy(data.data() + at, &value, sizeof(T));
  }
};

// x, y, z as packed FLOAT32, 12 bytes a point, one row (sensor_msgs' setPointCloud2Fields with x, y, z;
// depth_image_proc's point_cloud_xyz pads them to 16 bytes).
OwnedCloud packed(const std::vector<std::array<float, 3>>& points) {
  OwnedCloud c;
  c.header.height = 1;
  c.header.width = static_cast<std::uint32_t>(points.size());
  c.header.fields = {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1}};
  c.header.point_step = 12;
  c.header.row_step = 12 * c.header.width;
  c.data.resize(c.header.row_step);
  for (std::size_t i = 0; i < points.size(); ++i)
    for (std::size_t k = 0; k < 3; ++k) c.put(12 * i + 4 * k, points[i][k]);
  return c;
}

std::string refusal(const OwnedCloud& c) {
  try {
    (void)to_points(c.view());
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

void expect_point(const pcl::PointXYZ& p, float x, float y, float z) {
  EXPECT_EQ(p.x, x);
  EXPECT_EQ(p.y, y);
  EXPECT_EQ(p.z, z);
}

TEST(PointCloud2Test, PackedFloat32PointsComeOutInOrder) {
  const Cloud cloud = to_points(packed({{1.5f, -2.0f, 0.25f}, {0.0f, 0.0f, 3.0f}}).view());
  ASSERT_EQ(cloud.size(), 2u);
  expect_point(cloud[0], 1.5f, -2.0f, 0.25f);
  expect_point(cloud[1], 0.0f, 0.0f, 3.0f);
  EXPECT_EQ(cloud.height, 1u);
  EXPECT_EQ(cloud.width, 2u);
}

// FLOAT64 coordinates in another order and at other offsets, with an intensity field and padding: a 3D
// lidar's layout (x, y, z need not come first, nor in order).
TEST(PointCloud2Test, Float64FieldsAtAnyOffsetsAreRead) {
  OwnedCloud c;
  c.header.height = 1;
  c.header.width = 2;
  c.header.fields = {
      {"intensity", 0, kFloat32, 1}, {"z", 8, kFloat64, 1}, {"x", 16, kFloat64, 1}, {"y", 24, kFloat64, 1}};
  c.header.point_step = 40;
  c.header.row_step = 80;
  c.data.assign(80, 0xAB);
  c.put<double>(16, 0.125);
  c.put<double>(24, -7.5);
  c.put<double>(8, 2.0);
  c.put<double>(40 + 16, 1e-3);
  c.put<double>(40 + 24, 4.0);
  c.put<double>(40 + 8, -1.25);
  const Cloud cloud = to_points(c.view());
  ASSERT_EQ(cloud.size(), 2u);
  expect_point(cloud[0], 0.125f, -7.5f, 2.0f);
  expect_point(cloud[1], 1e-3f, 4.0f, -1.25f);
}

// An organized 2 × 3 cloud with 4 bytes of padding after each row; NaN and inf mark invalid points (is_dense
// false) and are left out, the rest keep row order.
TEST(PointCloud2Test, OrganizedRowsWithPaddingAndInvalidPoints) {
  OwnedCloud c = packed({});
  c.header.height = 2;
  c.header.width = 3;
  c.header.row_step = 3 * 12 + 4;
  c.data.assign(2 * c.header.row_step, 0);
  const float rows[2][3][3] = {{{1, 2, 3}, {kNaN, kNaN, kNaN}, {4, 5, 6}},
                               {{7, 8, kInf}, {9, 10, 11}, {12, 13, 14}}};
  for (int r = 0; r < 2; ++r)
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) c.put(std::size_t(r) * c.header.row_step + 12 * i + 4 * k, rows[r][i][k]);
  const Cloud cloud = to_points(c.view());
  ASSERT_EQ(cloud.size(), 4u);
  expect_point(cloud[0], 1, 2, 3);
  expect_point(cloud[1], 4, 5, 6);
  expect_point(cloud[2], 9, 10, 11);
  expect_point(cloud[3], 12, 13, 14);
}

// Mixed datatypes: x and z FLOAT32, y FLOAT64 (each coordinate read by its own datatype).
TEST(PointCloud2Test, MixedFloat32AndFloat64FieldsAreRead) {
  OwnedCloud c;
  c.header.height = 1;
  c.header.width = 2;
  c.header.fields = {{"x", 0, kFloat32, 1}, {"y", 8, kFloat64, 1}, {"z", 4, kFloat32, 1}};
  c.header.point_step = 16;
  c.header.row_step = 32;
  c.data.assign(32, 0);
  c.put<float>(0, 1.5f);
  c.put<double>(8, -0.25);
  c.put<float>(4, 2.0f);
  c.put<float>(16, kNaN);
  const Cloud cloud = to_points(c.view());
  ASSERT_EQ(cloud.size(), 1u);
  expect_point(cloud[0], 1.5f, -0.25f, 2.0f);
}

// A cloud of many rows longer than the points converted at a time, with padded rows and invalid points in
// runs and alone: the same points, in the same order, as reading each point on its own.
TEST(PointCloud2Test, LargeOrganizedCloudKeepsEveryValidPointInOrder) {
  OwnedCloud c;
  c.header.height = 37;
  c.header.width = 1013;
  c.header.fields = {
      {"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1}, {"rgb", 16, kFloat32, 1}};
  c.header.point_step = 32;
  c.header.row_step = 1013 * 32 + 8;
  c.data.assign(std::size_t{c.header.row_step} * c.header.height, 0);
  std::vector<std::array<float, 3>> expected;
  for (std::uint32_t row = 0; row < c.header.height; ++row) {
    for (std::uint32_t i = 0; i < c.header.width; ++i) {
      const std::uint32_t n = row * c.header.width + i;
      std::array<float, 3> p{0.001f * n, -0.5f * row, 1.0f + 0.25f * i};
      if ((n / 700) % 3 == 1) p[2] = kNaN;  // runs of invalid points, some across rows
      if (n % 97 == 0) p[0] = kInf;         // and single ones
      if (n % 89 == 0) p[1] = -kInf;
      for (std::size_t k = 0; k < 3; ++k) c.put(std::size_t{row} * c.header.row_step + 32 * i + 4 * k, p[k]);
      if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) expected.push_back(p);
    }
  }
  const Cloud cloud = to_points(c.view());
  ASSERT_EQ(cloud.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    expect_point(cloud[i], expected[i][0], expected[i][1], expected[i][2]);
    EXPECT_EQ(cloud[i].data[3], 1.0f);  // as pcl::PointXYZ(x, y, z) makes it
  }
  EXPECT_EQ(cloud.width, expected.size());
  EXPECT_EQ(cloud.height, 1u);
  EXPECT_TRUE(cloud.is_dense);
}

// realsense-ros's ordered clouds keep a pixel without depth as (0, 0, 0): not a point at the camera.
TEST(PointCloud2Test, PointsNearerThanMinRangeAreLeftOut) {
  const OwnedCloud c = packed({{0, 0, 0}, {0.03f, 0, 0}, {0, 0.04f, 0.04f}, {1, 2, 3}});
  EXPECT_EQ(to_points(c.view()).size(), 4u);
  const Cloud cloud = to_points(c.view(), 0.05f);
  ASSERT_EQ(cloud.size(), 2u);
  expect_point(cloud[0], 0, 0.04f, 0.04f);  // 5.7 cm away
  expect_point(cloud[1], 1, 2, 3);
}

TEST(PointCloud2Test, EmptyCloudGivesNoPoints) {
  EXPECT_TRUE(to_points(packed({}).view()).empty());
}

TEST(PointCloud2Test, MalformedCloudsAreRefusedWithTheirReason) {
  OwnedCloud big_endian = packed({{1, 2, 3}});
  big_endian.header.is_bigendian = true;
  EXPECT_THAT(refusal(big_endian), HasSubstr("big-endian"));

  OwnedCloud no_z = packed({{1, 2, 3}});
  no_z.header.fields.pop_back();
  EXPECT_EQ(refusal(no_z), "no field z");

  OwnedCloud int_z = packed({{1, 2, 3}});
  int_z.header.fields[2].datatype = static_cast<std::uint8_t>(PointFieldType::kInt16);
  EXPECT_THAT(refusal(int_z), HasSubstr("field z has datatype 3"));

  OwnedCloud no_count = packed({{1, 2, 3}});
  no_count.header.fields[0].count = 0;
  EXPECT_EQ(refusal(no_count), "field x has count 0");

  OwnedCloud past_point = packed({{1, 2, 3}});
  past_point.header.fields[2].offset = 10;
  EXPECT_THAT(refusal(past_point), HasSubstr("field z at offset 10 ends past point_step 12"));

  OwnedCloud short_row = packed({{1, 2, 3}, {4, 5, 6}});
  short_row.header.row_step = 20;
  EXPECT_THAT(refusal(short_row), HasSubstr("row_step 20 is shorter than width 2 x point_step 12"));

  OwnedCloud truncated = packed({{1, 2, 3}, {4, 5, 6}});
  truncated.data.resize(23);
  EXPECT_THAT(refusal(truncated), HasSubstr("data holds 23 bytes, not row_step 24 x height 1"));

  OwnedCloud huge = packed({});
  huge.header.width = 100000;
  huge.header.height = 100000;
  EXPECT_THAT(refusal(huge), HasSubstr("more than"));

  // Found by fuzz_ros2_samples: 4 billion empty rows passed every size check and took minutes.
  OwnedCloud tall = packed({});
  tall.header.height = 0xff000001u;
  tall.header.row_step = 0;
  EXPECT_THAT(refusal(tall), HasSubstr("more than"));
}

// width × point_step and row_step × height in 32 bits would wrap around and pass the size check.
TEST(PointCloud2Test, SizesThatOverflow32BitsAreRefused) {
  OwnedCloud c = packed({{1, 2, 3}});
  c.header.width = 1u << 20;
  c.header.point_step = 1u << 12;  // width × point_step = 2^32
  c.header.row_step = 0;
  EXPECT_THAT(refusal(c), HasSubstr("row_step 0 is shorter"));
}

}  // namespace
}  // namespace cellmap::ros2
