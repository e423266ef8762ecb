// SPDX-License-Identifier: Apache-2.0
#pragma once
// The robot's surface as points, for tests that ask whether a box of the environment lies on the robot.

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/robot/joint_state.hpp"
#include "cellmap/robot/robot.hpp"
#include "cellmap/sim/scene.hpp"

namespace cellmap::test {

// Points of one triangle on a barycentric grid at most `spacing` apart along its longest edge.
inline void sample_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                            double spacing, std::vector<Eigen::Vector3d>& out) {
  const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  const int n = std::max(1, static_cast<int>(std::ceil(longest / spacing)));
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      out.push_back(a + (b - a) * (static_cast<double>(i) / n) + (c - a) * (static_cast<double>(j) / n));
    }
  }
}

/// Points on the surfaces of the robot's collision shapes at `state` (and of its payload), cell frame, about
/// `spacing` apart, on the links from `first_link` (index into link_names()) to the tool.
inline std::vector<Eigen::Vector3d> robot_surface(const Robot& robot, const JointState& state, double spacing,
                                                  int first_link = 0) {
  std::vector<Eigen::Vector3d> points;
  const std::vector<Eigen::Isometry3d> X_CG = robot.shape_poses(state.q);
  for (std::size_t i = 0; i < robot.shapes().size(); ++i) {
    if (robot.shape_links()[i] < first_link) continue;
    const LinkGeometry& geometry = robot.shapes()[i].geometry;
    if (const auto* mesh = std::get_if<MeshShape>(&geometry)) {
      for (const Eigen::Vector3i& t : mesh->mesh->triangles) {
        sample_triangle(X_CG[i] * mesh->mesh->vertices[static_cast<std::size_t>(t.x())],
                        X_CG[i] * mesh->mesh->vertices[static_cast<std::size_t>(t.y())],
                        X_CG[i] * mesh->mesh->vertices[static_cast<std::size_t>(t.z())], spacing, points);
      }
      continue;
    }
    sim::Obstacle solid;
    std::visit(
        [&](const auto& shape) {
          if constexpr (!std::is_same_v<std::decay_t<decltype(shape)>, MeshShape>) solid.shape = shape;
        },
        geometry);
    solid.X_CO = X_CG[i];
    for (const Eigen::Vector3d& p : solid.sample_surface(spacing)) points.push_back(p);
  }
  if (state.payload) {
    sim::Obstacle payload{"payload", BoxShape{state.payload->half_extents},
                          robot.tool_pose(state.q) * state.payload->X_EB};
    for (const Eigen::Vector3d& p : payload.sample_surface(spacing)) points.push_back(p);
  }
  return points;
}

/// The arm's links that move through the cell: from link_2 (the upper arm) on. Its base and turret
/// (base_link, link_1) stand on the pedestal beside the table; the one box the segmentation fits over floor,
/// table and pedestal from the fixed camera's view reaches over the gap between them into the turret.
inline constexpr int kArmWorkingLinks = 2;

/// Ids of the boxes holding a point of `surface`.
inline std::vector<std::uint64_t> boxes_holding_any(const std::vector<Box>& boxes,
                                                    const std::vector<Eigen::Vector3d>& surface) {
  std::vector<std::uint64_t> ids;
  for (const Box& box : boxes) {
    if (std::any_of(surface.begin(), surface.end(),
                    [&](const Eigen::Vector3d& p) { return box.contains(p); }))
      ids.push_back(box.id);
  }
  return ids;
}

}  // namespace cellmap::test
