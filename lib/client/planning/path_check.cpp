// SPDX-License-Identifier: Apache-2.0
#include "cellmap/planning/path_check.hpp"

#include <string>

#include "cellmap/collision/box_distance.hpp"
#include "cellmap/common/error.hpp"

namespace cellmap::planning {

std::vector<std::vector<collision::Obb>> place_along(const collision::RobotBoxes& robot,
                                                     const BSplinePath& path, int n) {
  const int dof = robot.robot().dof();
  if (path.control_points().front().size() != dof) {
    throw Error("path check: path points have " + std::to_string(path.control_points().front().size()) +
                " coordinates, the robot has " + std::to_string(dof) + " joints");
  }
  std::vector<std::vector<collision::Obb>> out;
  for (const Eigen::VectorXd& q : path.sample(n)) out.push_back(robot.place(q));
  return out;
}

collision::ConstraintSet path_constraints(const collision::RobotBoxes& robot, const BSplinePath& path,
                                          int n_checkpoints, const std::vector<collision::Obb>& environment) {
  return collision::constraints(place_along(robot, path, n_checkpoints), environment);
}

PathEnvironment::PathEnvironment(const std::vector<Box>& boxes, PathCheckOptions options)
    : tree_(keep(boxes, options)) {}

const std::vector<collision::Obb>& PathEnvironment::keep(const std::vector<Box>& boxes,
                                                         PathCheckOptions options) {
  obbs_.reserve(boxes.size());
  ids_.reserve(boxes.size());
  spaces_.reserve(boxes.size());
  for (const Box& box : boxes) {
    if (options.ignore_unknown && box.space == BoxSpace::kUnknown) {
      ++ignored_;
      continue;
    }
    obbs_.push_back(collision::to_obb(box));
    ids_.push_back(box.id);
    spaces_.push_back(box.space);
  }
  return obbs_;
}

Blocking path_blocked(const collision::RobotBoxes& robot, const BSplinePath& path, int n_checkpoints,
                      const std::vector<collision::Obb>& environment, const collision::BoxTree& tree,
                      double margin) {
  if (!(margin >= 0.0)) throw Error("path check: margin must be >= 0");
  const auto placed = place_along(robot, path, n_checkpoints);
  std::vector<int> near;
  for (int k = 0; k < n_checkpoints; ++k) {
    for (int r = 0; r < static_cast<int>(placed[k].size()); ++r) {
      const collision::Obb& box = placed[k][r];
      near.clear();
      // Bounds closer than the margin (or touching) are the only candidates.
      tree.query(box.center, box.aabb_half_extents(), margin, &near);
      for (const int e : near) {
        if (!collision::overlap(box, environment[e], margin)) continue;  // separated by >= margin on an axis
        const collision::SignedDistance pair = collision::signed_distance(box, environment[e]);
        if (pair.distance >= margin) continue;
        Blocking blocking;
        blocking.blocked = true;
        blocking.checkpoint = k;
        blocking.robot_box = r;
        blocking.env_box = e;
        blocking.distance = pair.distance;
        blocking.t = n_checkpoints == 1 ? 0.0 : static_cast<double>(k) / (n_checkpoints - 1);
        blocking.point = pair.point_b;
        return blocking;
      }
    }
  }
  return {};
}

Blocking path_blocked(const collision::RobotBoxes& robot, const BSplinePath& path, int n_checkpoints,
                      const PathEnvironment& environment, double margin) {
  Blocking blocking =
      path_blocked(robot, path, n_checkpoints, environment.obbs(), environment.tree(), margin);
  if (blocking.blocked) {
    blocking.box_id = environment.id(blocking.env_box);
    blocking.space = environment.space(blocking.env_box);
  }
  return blocking;
}

}  // namespace cellmap::planning
