// SPDX-License-Identifier: Apache-2.0
#include "cellmap/cell/cloud_boxes.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "coverage.hpp"

namespace cellmap {

CloudBoxes boxes_of_cloud(const Cloud& points_C, const CellPipelineConfig& config) {
  const auto start = std::chrono::steady_clock::now();
  CloudBoxes result;
  result.points = points_C.size();
  CellPipeline pipeline(config);
  result.outside_map = pipeline.settle_on(points_C);
  const Resegmentation first = pipeline.resegment_everything();
  result.boxes.version = 1;
  result.boxes.frame = "cell";
  for (Box box : first.reconciled.boxes) {
    box.id = result.boxes.boxes.size() + 1;
    result.boxes.boxes.push_back(box);
  }

  const OccupancyMap& map = pipeline.map();
  const OccupiedVoxels voxels(map);
  result.voxels = voxels.keys().size();
  for (const octomap::OcTreeKey& key : voxels.keys())
    result.noise_voxels += voxels.in_group_of(key, config.change.min_voxels) ? 0 : 1;
  // Boxes hold whole voxels; the tolerance is float rounding of the points.
  constexpr double kTolerance = 1e-6;
  for (const pcl::PointXYZ& p : points_C) {
    const Eigen::Vector3d p_C = p.getVector3fMap().cast<double>();
    if (map.state(p_C) != VoxelState::occupied) continue;  // outside the key range: counted above
    if (!voxels.in_group_of(map, p_C, config.change.min_voxels)) {
      ++result.noise_points;
    } else if (std::none_of(result.boxes.boxes.begin(), result.boxes.boxes.end(),
                            [&](const Box& box) { return box.contains(p_C, kTolerance); })) {
      ++result.outside_boxes;
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string summary(const CloudBoxes& r) {
  char line[256];
  std::snprintf(line, sizeof line,
                "points %zu (outside the map %zu), voxels %zu (noise %zu holding %zu points), boxes %zu, "
                "points outside every box %zu, time %.3f s",
                r.points, r.outside_map, r.voxels, r.noise_voxels, r.noise_points, r.boxes.boxes.size(),
                r.outside_boxes, r.seconds);
  return line;
}

}  // namespace cellmap
