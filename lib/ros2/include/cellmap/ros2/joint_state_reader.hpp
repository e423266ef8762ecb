// SPDX-License-Identifier: Apache-2.0
#pragma once
// The robot's joints from ROS 2: sensor_msgs/msg/JointState samples (ros2_control's joint_state_broadcaster
// on /joint_states) as cellmap's joint samples, an alternative to cellmap/robot_joints.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/input_limits.hpp"
#include "cellmap/transport/messages.hpp"

namespace cellmap::ros2 {

/// Reads one JointState topic for one robot. Read BEST_EFFORT (matching publishers of either kind), KEEP_LAST
/// 256. `participant` must outlive it. Not thread-safe.
class JointStateReader final {
 public:
  /// @param topic           ROS 2 topic, e.g. "/joint_states"
  /// @param cell            the cell the samples are given to (RobotJoints::cell)
  /// @param joint_names     the robot model's joints in its order
  /// @param max_stamp_skew  samples stamped farther than this from now are refused; zero: not checked
  /// @throws Error if the topic name is not a ROS 2 one, joint_names is empty or the reader cannot be made.
  JointStateReader(const dds::Participant& participant, std::string topic, std::string cell,
                   std::vector<std::string> joint_names, std::chrono::nanoseconds max_stamp_skew,
                   transport::OnRefused on_refused);
  ~JointStateReader();
  JointStateReader(const JointStateReader&) = delete;
  JointStateReader& operator=(const JointStateReader&) = delete;

  /// Waits up to `timeout` for data (zero: just looks) and returns the samples received, oldest first, with
  /// the robot's joint names and positions in its order (ros2::in_robot_order: other joints ignored). A
  /// sample missing one of the robot's joints, with a non-finite position, names and positions of different
  /// counts or stamped too far from now is refused: counted in rejected(), passed to on_refused.
  std::vector<transport::RobotJoints> take(std::chrono::nanoseconds timeout = std::chrono::nanoseconds(0));
  [[nodiscard]] std::uint64_t rejected() const { return rejected_; }
  [[nodiscard]] const std::string& topic() const { return topic_name_; }

 private:
  std::string topic_name_;
  std::string cell_;
  std::vector<std::string> joint_names_;
  std::chrono::nanoseconds max_stamp_skew_;
  transport::OnRefused on_refused_;
  dds::Topic topic_;
  dds::Reader reader_;
  dds::WaitSet waitset_;
  std::uint64_t rejected_ = 0;
};

}  // namespace cellmap::ros2
