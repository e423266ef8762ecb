// SPDX-License-Identifier: Apache-2.0
#pragma once
// Scoring collision boxes against a simulated scene's true obstacles (the paper's sensor comparison).
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/frame/cloud.hpp"
#include "cellmap/sim/scene.hpp"

namespace cellmap::sim {

/// How well the boxes stand for one obstacle.
struct ObjectScore final {
  std::string name;
  /// Volumetric IoU of the best-matching box with the obstacle's tight box (the box itself; a cylinder's or a
  /// sphere's circumscribed box): 1 when one box is exactly the object's own.
  double iou = 0.0;
  std::uint64_t box = 0;  ///< id of that box; 0 when no box overlaps the obstacle's tight box
};

/// The obstacle's tight box: the smallest box holding the solid, id 0.
[[nodiscard]] Box tight_box(const Obstacle& obstacle);

/// How well a set of boxes stands for the true obstacles inside an evaluation region.
struct BoxScore final {
  std::size_t boxes = 0;
  std::size_t surface_points = 0;  ///< true surface points inside the region
  /// Share of the true surface points that lie inside some box (a missed surface is a possible collision).
  double coverage = 0.0;
  double true_volume = 0.0;  ///< m³ of the region inside some obstacle
  double box_volume = 0.0;   ///< m³ of the region inside some box (overlaps counted once)
  /// (box_volume − true_volume) / true_volume: workspace the boxes take beyond the objects' own volume.
  double lost_free_space = 0.0;
  /// m³ of the region inside some box but inside no obstacle, over true_volume (the free space boxes block).
  double blocked_free_space = 0.0;
  /// Share of the true obstacle volume inside some box (the objects' inside and hidden parts included).
  double volume_coverage = 0.0;
  /// One per obstacle whose centre lies in the region, in scene order.
  std::vector<ObjectScore> objects;

  /// Median of the objects' IoU (0 without objects).
  [[nodiscard]] double median_iou() const;
};

/// Scores `boxes` against `obstacles` in `region`. `true_surface_C` is the surface the boxes should cover,
/// e.g. the exact (zero-noise) cloud of the same sweep; points outside the region are ignored. Volumes are
/// counted on a grid of `voxel` metres (cell centres), so they are exact to about one voxel layer of each
/// surface; the objects' IoU is exact (boxes/volume.hpp). Cost: one containment test per voxel inside each
/// box's and obstacle's bounding box, and one box overlap per box and object.
/// @throws Error if `voxel` is not positive, the region is empty, or it holds no obstacle volume.
[[nodiscard]] BoxScore score_boxes(const std::vector<Obstacle>& obstacles, const std::vector<Box>& boxes,
                                   const Cloud& true_surface_C, const Region& region, double voxel = 0.01,
                                   double tolerance = 0.001);

}  // namespace cellmap::sim
