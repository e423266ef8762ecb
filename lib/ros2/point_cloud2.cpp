// SPDX-License-Identifier: Apache-2.0
#include "cellmap/ros2/point_cloud2.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "cellmap/common/error.hpp"

namespace cellmap::ros2 {
namespace {

// Where one coordinate lies in a point and how wide it is.
struct Coordinate final {
  std::uint32_t offset = 0;
  bool is_double = false;
};

Coordinate find_coordinate(const PointCloud2View& msg, const char* name) {
  for (const PointField& field : msg.fields) {
    if (field.name != name) continue;
    const auto type = static_cast<PointFieldType>(field.datatype);
    if (type != PointFieldType::kFloat32 && type != PointFieldType::kFloat64) {
      throw Error(std::string("field ") + name + " has datatype " + std::to_string(field.datatype) +
                  ", not FLOAT32 (7) or FLOAT64 (8)");
    }
    if (field.count == 0) throw Error(std::string("field ") + name + " has count 0");
    const Coordinate c{field.offset, type == PointFieldType::kFloat64};
    const std::uint64_t end = std::uint64_t{c.offset} + (c.is_double ? 8 : 4);
    if (end > msg.point_step) {
      throw Error(std::string("field ") + name + " at offset " + std::to_string(field.offset) +
                  " ends past point_step " + std::to_string(msg.point_step));
    }
    return c;
  }
  throw Error(std::string("no field ") + name);
}

void check_layout(const PointCloud2View& msg) {
  if (msg.is_bigendian) throw Error("big-endian clouds are not supported");
  const std::uint64_t points = std::uint64_t{msg.width} * msg.height;
  // Each bounded on its own too: a huge height times a width of 0 would pass and loop over empty rows.
  if (points > kMaxCloudPoints || msg.width > kMaxCloudPoints || msg.height > kMaxCloudPoints) {
    throw Error(std::to_string(msg.width) + " x " + std::to_string(msg.height) + " points, more than " +
                std::to_string(kMaxCloudPoints));
  }
  if (std::uint64_t{msg.width} * msg.point_step > msg.row_step) {
    throw Error("row_step " + std::to_string(msg.row_step) + " is shorter than width " +
                std::to_string(msg.width) + " x point_step " + std::to_string(msg.point_step));
  }
  if (std::uint64_t{msg.row_step} * msg.height != msg.data_size) {
    throw Error("data holds " + std::to_string(msg.data_size) + " bytes, not row_step " +
                std::to_string(msg.row_step) + " x height " + std::to_string(msg.height));
  }
}

template <typename T>
float read(const std::uint8_t* at) {
  T value;
  std::memcpy(&value, at, sizeof(T));
  return static_cast<float>(value);
}

float read(const std::uint8_t* point, const Coordinate& c) {
  return c.is_double ? read<double>(point + c.offset) : read<float>(point + c.offset);
}

// Points are gathered a block at a time, without a branch on each point's validity, and appended with one
// copy: a push_back per point (its capacity check and PCL's width and height updates) cost more than reading
// the point (`cellmap bench ros2`). 512 points are 8 KiB, within L1.
constexpr std::uint32_t kBlock = 512;
// A block is appended once fewer slots than this are left, so that the loop over a row runs long stretches.
constexpr std::uint32_t kMinStretch = 64;

// Appends to `cloud` the points of `msg` whose x, y and z, read as floats by `read_xyz(point, p)`, are all
// finite and lie at least sqrt(min_range2) from the origin, in row order.
template <typename ReadXyz>
void append_valid(const PointCloud2View& msg, float min_range2, const ReadXyz& read_xyz, Cloud& cloud) {
  // Each point's 4th float stays 1, as pcl::PointXYZ(x, y, z) sets it.
  std::array<pcl::PointXYZ, kBlock> block;
  std::uint32_t filled = 0;
  const auto flush = [&] {
    cloud.points.insert(cloud.points.end(), block.begin(), block.begin() + filled);
    filled = 0;
  };
  for (std::uint32_t row = 0; row < msg.height; ++row) {
    const std::uint8_t* point = msg.data + std::size_t{row} * msg.row_step;
    for (std::uint32_t left = msg.width; left > 0;) {
      const std::uint32_t stretch = std::min(left, kBlock - filled);
      for (std::uint32_t i = 0; i < stretch; ++i, point += msg.point_step) {
        pcl::PointXYZ& p = block[filled];
        read_xyz(point, p);
        const bool finite = std::isfinite(p.x) & std::isfinite(p.y) & std::isfinite(p.z);
        filled += static_cast<std::uint32_t>(finite & (p.x * p.x + p.y * p.y + p.z * p.z >= min_range2));
      }
      left -= stretch;
      if (kBlock - filled < kMinStretch) flush();
    }
  }
  flush();
}

}  // namespace

Cloud to_points(const PointCloud2View& msg, float min_range) {
  check_layout(msg);
  const float min_range2 = min_range * min_range;
  const Coordinate x = find_coordinate(msg, "x"), y = find_coordinate(msg, "y"),
                   z = find_coordinate(msg, "z");
  Cloud cloud;
  cloud.reserve(std::size_t{msg.width} * msg.height);
  // Each layout of the coordinates its own loop: all FLOAT32 (depth cameras and most lidars), all FLOAT64, or
  // mixed, which reads each coordinate by its datatype.
  if (!x.is_double && !y.is_double && !z.is_double) {
    append_valid(
        msg, min_range2,
        [xo = x.offset, yo = y.offset, zo = z.offset](const std::uint8_t* point, pcl::PointXYZ& p) {
          p.x = read<float>(point + xo);
          p.y = read<float>(point + yo);
          p.z = read<float>(point + zo);
        },
        cloud);
  } else if (x.is_double && y.is_double && z.is_double) {
    append_valid(
        msg, min_range2,
        [xo = x.offset, yo = y.offset, zo = z.offset](const std::uint8_t* point, pcl::PointXYZ& p) {
          p.x = read<double>(point + xo);
          p.y = read<double>(point + yo);
          p.z = read<double>(point + zo);
        },
        cloud);
  } else {
    append_valid(
        msg, min_range2,
        [&](const std::uint8_t* point, pcl::PointXYZ& p) {
          p.x = read(point, x);
          p.y = read(point, y);
          p.z = read(point, z);
        },
        cloud);
  }
  set_unorganized(cloud);
  return cloud;
}

}  // namespace cellmap::ros2
