// SPDX-License-Identifier: Apache-2.0
#pragma once
// sensor_msgs/msg/JointState → the robot's joint positions: what ros2_control's joint_state_broadcaster
// publishes on /joint_states, matched to the robot model's joints by name.

#include <cstddef>
#include <string>
#include <vector>

namespace cellmap::ros2 {

/// The most names a JointState may carry (every robot of a cell on one topic is far fewer).
inline constexpr std::size_t kMaxJointStateNames = 1024;

/// The positions of `robot_joints` (the model's joints, in its order) taken from a JointState's `names`
/// and `positions` (in any order; joints the robot does not have, e.g. a gripper's, are ignored; a
/// broadcaster may publish several robots' joints on one topic). Pure function; thread-safe.
/// @throws Error with one line naming the joint: more than kMaxJointStateNames names, names and positions
/// differ in count, a name repeats, one
/// of the robot's joints is missing, or its position is not finite.
[[nodiscard]] std::vector<double> in_robot_order(const std::vector<std::string>& names,
                                                 const std::vector<double>& positions,
                                                 const std::vector<std::string>& robot_joints);

}  // namespace cellmap::ros2
