// SPDX-License-Identifier: Apache-2.0
#pragma once
// Path checks for planners: a B-spline path sampled at N checkpoints, every robot box against every
// environment box.

#include <vector>

#include "cellmap/collision/batch.hpp"
#include "cellmap/collision/box_tree.hpp"
#include "cellmap/collision/robot_boxes.hpp"
#include "cellmap/planning/bspline.hpp"

namespace cellmap::planning {

/// The robot's boxes in the cell frame at each of the n checkpoints of `path` (whose points are joint vectors
/// of robot.robot()). @throws Error if n < 1 or the path's dimension is not the robot's dof.
[[nodiscard]] std::vector<std::vector<collision::Obb>> place_along(const collision::RobotBoxes& robot,
                                                                   const BSplinePath& path, int n);

/// The constraint vector of the path: n_constr = n_rob · n_env · N entries with distance, witness points and
/// normal (see collision::constraints). @throws Error as place_along.
[[nodiscard]] collision::ConstraintSet path_constraints(const collision::RobotBoxes& robot,
                                                        const BSplinePath& path, int n_checkpoints,
                                                        const std::vector<collision::Obb>& environment);

/// Where a path first violates the safety margin δ, if it does.
struct Blocking final {
  bool blocked = false;
  int checkpoint = -1;
  int robot_box = -1;
  int env_box = -1;
  double distance = 0.0;  ///< signed distance of that pair (< margin)
};

/// "Is the path blocked?": walks checkpoints in order and stops at the first pair closer than `margin` (>=
/// 0). The broad phase (`tree` over `environment`) skips far boxes; the separating-axis test rejects most of
/// the rest before an exact distance is computed. @throws Error as place_along, or if margin < 0.
[[nodiscard]] Blocking path_blocked(const collision::RobotBoxes& robot, const BSplinePath& path,
                                    int n_checkpoints, const std::vector<collision::Obb>& environment,
                                    const collision::BoxTree& tree, double margin);

}  // namespace cellmap::planning
