// SPDX-License-Identifier: Apache-2.0
#include "cellmap/collision/robot_boxes.hpp"

#include <algorithm>

#include "cellmap/common/error.hpp"

namespace cellmap::collision {

RobotBoxes::RobotBoxes(Robot robot) : RobotBoxes(robot, robot.shape_boxes()) {}

RobotBoxes::RobotBoxes(Robot robot, std::vector<LinkBox> boxes)
    : robot_(std::move(robot)), boxes_(std::move(boxes)) {
  const std::vector<std::string>& links = robot_.link_names();
  for (std::size_t i = 0; i < boxes_.size(); ++i) {
    const LinkBox& box = boxes_[i];
    const std::string where = "robot box " + std::to_string(i) + " (link '" + box.link + "')";
    const auto it = std::find(links.begin(), links.end(), box.link);
    if (it == links.end()) throw Error(where + ": the robot has no such link");
    if (!box.half_extents.allFinite() || (box.half_extents.array() < 0.0).any()) {
      throw Error(where + ": half extents must be finite and >= 0");
    }
    if (!box.X_LB.matrix().allFinite()) throw Error(where + ": X_LB must be finite");
    link_index_.push_back(static_cast<int>(it - links.begin()));
  }
}

std::vector<Obb> RobotBoxes::place(const Eigen::VectorXd& q) const {
  const std::vector<Eigen::Isometry3d> X_CL = robot_.link_poses(q);
  std::vector<Obb> out;
  out.reserve(boxes_.size());
  for (std::size_t i = 0; i < boxes_.size(); ++i) {
    const Eigen::Isometry3d X_CB = X_CL[link_index_[i]] * boxes_[i].X_LB;
    out.emplace_back(X_CB.translation(), boxes_[i].half_extents, X_CB.linear());
  }
  return out;
}

}  // namespace cellmap::collision
