// SPDX-License-Identifier: Apache-2.0
#pragma once
// The point cloud type the map-making stages exchange (PCL; the planner's client never sees it).

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>

namespace cellmap {

/// Points in metres. Which frame they are in is part of each variable's name (`points_C` cell, `points_S`
/// sensor). Unorganized unless a function says otherwise.
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

/// Sets `cloud`'s header to what its points are after they were filled directly: one row of valid points.
inline void set_unorganized(Cloud& cloud) {
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
}

}  // namespace cellmap
