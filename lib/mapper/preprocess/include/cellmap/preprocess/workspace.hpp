// SPDX-License-Identifier: Apache-2.0
#pragma once
// The robot's reachable workspace, used to crop clouds to what can matter for collisions.

#include <Eigen/Core>

#include <cstdint>
#include <unordered_set>
#include <vector>

#include "cellmap/common/region.hpp"
#include "cellmap/frame/cloud.hpp"

namespace cellmap {

class Robot;

/// A region of the cell frame C: either an axis-aligned box, or a set of voxels (edge `voxel`, metres) that
/// covers sampled reachable points grown by a tool envelope. Immutable value; an object that exists is valid.
class Workspace final {
 public:
  /// The box [lower, upper] in C (metres). @throws Error if lower > upper on an axis or a value is not
  /// finite.
  [[nodiscard]] static Workspace box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper);
  /// The voxels of edge `voxel` within `envelope` metres of any of `points_C` (a voxel counts when its centre
  /// is within envelope + half the voxel diagonal, so the region covers every point within `envelope`).
  /// @throws Error if points_C is empty, voxel <= 0, envelope < 0 or a value is not finite.
  [[nodiscard]] static Workspace from_points(const std::vector<Eigen::Vector3d>& points_C, double envelope,
                                             double voxel);

  /// True if p_C lies inside the region.
  [[nodiscard]] bool contains(const Eigen::Vector3d& p_C) const;
  [[nodiscard]] bool is_box() const { return voxel_ == 0.0; }
  [[nodiscard]] const Region& bounds() const { return bounds_; }  ///< bounding box of the region
  [[nodiscard]] std::size_t voxel_count() const { return voxels_.size(); }

 private:
  Workspace() = default;
  [[nodiscard]] std::int64_t key(const Eigen::Vector3d& p_C) const;

  Region bounds_;
  double voxel_ = 0.0;  // 0 for a box
  std::unordered_set<std::int64_t> voxels_;
};

/// The region the robot's tool can reach, grown by `tool_envelope` metres (the tool's and its load's size).
/// A chain of prismatic joints only (a linear/gantry robot) sweeps a parallelepiped: the result is the box
/// around the tool positions at its 2^dof corner configurations, grown by the envelope. Any other chain is
/// sampled: `samples` values per joint, evenly over its limits (samples^dof configurations, tool positions by
/// FK), voxelised at `voxel` metres with Workspace::from_points. Sampling covers the reachable set only when
/// neighbouring samples' tool positions lie within about tool_envelope of each other: choose samples so.
/// @throws Error if samples < 2, samples^dof > 1e6, voxel <= 0 or tool_envelope < 0.
[[nodiscard]] Workspace workspace_from_robot(const Robot& robot, double tool_envelope, int samples,
                                             double voxel);

/// Indices (ascending) of the points of `cloud` inside `workspace`.
[[nodiscard]] std::vector<int> crop_to_workspace(const Cloud& cloud, const Workspace& workspace);

}  // namespace cellmap
