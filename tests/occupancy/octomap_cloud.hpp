// SPDX-License-Identifier: Apache-2.0
#pragma once
// Test support: a scan as OctoMap's point cloud, for the tests that compare the occupancy stage with
// OctoMap's own insert.

#include <octomap/Pointcloud.h>

#include "cellmap/sweep/sweep.hpp"

namespace cellmap::testing {

/// The scan's points in the cell frame, in order.
inline octomap::Pointcloud to_octomap(const Scan& scan) {
  octomap::Pointcloud cloud;
  for (const auto& p : scan.points_C.points) cloud.push_back(p.x, p.y, p.z);
  return cloud;
}

}  // namespace cellmap::testing
