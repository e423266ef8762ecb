#pragma once
// The point cloud type the map-making stages exchange (PCL; the planner's client never sees it).

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace cellmap {

/// Points in metres. Which frame they are in is part of each variable's name (`points_C` cell, `points_S`
/// sensor). Unorganized unless a function says otherwise.
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

}  // namespace cellmap
