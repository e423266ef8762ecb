// SPDX-License-Identifier: Apache-2.0
#pragma once
// A robot's collision geometry: boxes fixed to its links, placed in the cell frame by forward kinematics.

#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "cellmap/collision/obb.hpp"
#include "cellmap/robot/robot.hpp"

namespace cellmap::collision {

/// A Robot with boxes on its links. Immutable and valid once built; safe to share between threads.
class RobotBoxes final {
 public:
  /// The tight box of each of the robot's collision shapes (Robot::shape_boxes): the geometry the map
  /// maker's self filter and simulator use, so planner and map maker agree on where the robot is.
  explicit RobotBoxes(Robot robot);
  /// @throws Error naming the box index if its link is not one of robot.link_names(), a half extent is
  /// negative or a value is not finite.
  RobotBoxes(Robot robot, std::vector<LinkBox> boxes);

  /// The boxes in the cell frame C at joint vector q (X_CB = X_CL(q) * X_LB), in the order given.
  /// @throws Error as Robot::link_poses (wrong size or non-finite q).
  [[nodiscard]] std::vector<Obb> place(const Eigen::VectorXd& q) const;

  [[nodiscard]] const Robot& robot() const { return robot_; }
  [[nodiscard]] const std::vector<LinkBox>& boxes() const { return boxes_; }
  [[nodiscard]] int size() const { return static_cast<int>(boxes_.size()); }

 private:
  Robot robot_;
  std::vector<LinkBox> boxes_;
  std::vector<int> link_index_;  // index into robot_.link_names() per box
};

}  // namespace cellmap::collision
