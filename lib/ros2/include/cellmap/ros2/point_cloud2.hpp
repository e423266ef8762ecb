// SPDX-License-Identifier: Apache-2.0
#pragma once
// sensor_msgs/msg/PointCloud2 → points: what any ROS 2 depth camera or 3D lidar driver publishes, read for x,
// y and z wherever the cloud's layout puts them.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cellmap/frame/cloud.hpp"

namespace cellmap::ros2 {

/// sensor_msgs/msg/PointField's datatype values.
enum class PointFieldType : std::uint8_t {
  kInt8 = 1,
  kUint8 = 2,
  kInt16 = 3,
  kUint16 = 4,
  kInt32 = 5,
  kUint32 = 6,
  kFloat32 = 7,
  kFloat64 = 8,
};

/// One sensor_msgs/msg/PointField: `count` values of `datatype` at byte `offset` of each point.
struct PointField final {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;
  std::uint32_t count = 0;
};

/// A received sensor_msgs/msg/PointCloud2 with its data borrowed (not owned): valid while the sample is.
struct PointCloud2View final {
  std::uint32_t height = 0;  ///< rows; 1 for an unorganized cloud
  std::uint32_t width = 0;   ///< points per row
  std::vector<PointField> fields;
  bool is_bigendian = false;
  std::uint32_t point_step = 0;  ///< bytes from one point to the next in a row
  std::uint32_t row_step = 0;    ///< bytes from one row to the next
  const std::uint8_t* data = nullptr;
  std::size_t data_size = 0;
};

/// The largest cloud accepted, points (a 4K depth image is 8.3 M; 3D lidars send 0.1–2.6 M).
inline constexpr std::uint64_t kMaxCloudPoints = 16'000'000;

/// The points of `msg` in its own frame, row by row: every point whose x, y and z are all finite (NaN and
/// inf mark invalid points, whatever is_dense says) and that lies at least `min_range` metres from the
/// frame's origin (some drivers keep a pixel without depth as (0, 0, 0)). x, y and z are FLOAT32 or FLOAT64
/// fields at any offsets within point_step; other fields are ignored. Pure function; thread-safe.
/// @throws Error with one line saying what is wrong: a big-endian cloud, no x, y or z field, one of another
/// datatype or with count 0, a field past point_step, a row shorter than width × point_step, data whose
/// size is not row_step × height, or more than kMaxCloudPoints points.
[[nodiscard]] Cloud to_points(const PointCloud2View& msg, float min_range = 0.0f);

}  // namespace cellmap::ros2
