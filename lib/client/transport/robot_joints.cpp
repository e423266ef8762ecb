// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/robot_joints.hpp"

#include <algorithm>
#include <set>
#include <utility>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "cellmap/transport/topics.hpp"
#include "wire.hpp"

namespace cellmap::transport {

RobotJoints in_robot_order(RobotJoints joints, const std::vector<std::string>& joint_names) {
  const std::string where = wire::sample_name(kRobotJointsTopic, joints.cell, joints.stamp_ns);
  if (joints.positions.size() != joint_names.size()) {
    throw Error(where + ": " + std::to_string(joints.positions.size()) + " positions, the robot has " +
                std::to_string(joint_names.size()) + " joints");
  }
  if (joints.names.empty()) {
    joints.names = joint_names;
    return joints;
  }
  std::vector<double> ordered(joint_names.size());
  std::vector<bool> seen(joint_names.size(), false);
  for (std::size_t i = 0; i < joints.names.size(); ++i) {
    const auto it = std::find(joint_names.begin(), joint_names.end(), joints.names[i]);
    if (it == joint_names.end()) throw Error(where + ": unknown joint " + wire::quote_input(joints.names[i]));
    const auto k = static_cast<std::size_t>(it - joint_names.begin());
    if (seen[k]) throw Error(where + ": joint " + wire::quote_input(joints.names[i]) + " given twice");
    seen[k] = true;
    ordered[k] = joints.positions[i];
  }
  joints.names = joint_names;
  joints.positions = std::move(ordered);
  return joints;
}

RobotJointsWriter::RobotJointsWriter(const dds::Participant& participant, std::string cell)
    : cell_(one_cell(std::move(cell), std::string(kRobotJointsTopic) + " writer")),
      topic_(participant, &cellmap_msg_RobotJoints_desc, kRobotJointsTopic),
      writer_(participant, topic_, in_cell(robot_joints_qos(), cell_)) {}

bool RobotJointsWriter::wait_for_reader(std::chrono::nanoseconds timeout) const {
  return writer_.wait_for_readers(1, timeout);
}

void RobotJointsWriter::write(const RobotJoints& joints) const {
  wire::validate(joints);
  if (joints.cell != cell_) {
    throw Error(std::string(kRobotJointsTopic) + " " + wire::quote_input(joints.cell) +
                ": this writer is for cell '" + cell_ + "'");
  }
  const wire::RobotJointsSample sample(joints);
  writer_.write(sample.get());
}

bool RobotJointsWriter::wait_for_acks(std::chrono::nanoseconds timeout) const {
  return writer_.wait_for_acks(timeout);
}

RobotJointsReader::RobotJointsReader(const dds::Participant& participant, std::string cell,
                                     std::vector<std::string> joint_names, InputLimits limits,
                                     OnRefused on_refused)
    : cell_(one_cell(std::move(cell), std::string(kRobotJointsTopic) + " reader")),
      joint_names_(std::move(joint_names)),
      limits_(std::move(limits)),
      on_refused_(std::move(on_refused)),
      topic_(participant, &cellmap_msg_RobotJoints_desc, kRobotJointsTopic),
      reader_(participant, topic_, in_cell(robot_joints_qos(), cell_)),
      waitset_(participant) {
  const std::string where = std::string(kRobotJointsTopic) + " reader";
  if (joint_names_.empty()) throw Error(where + ": the robot has no joints");
  if (std::set<std::string>(joint_names_.begin(), joint_names_.end()).size() != joint_names_.size()) {
    throw Error(where + ": joint names repeat");
  }
  waitset_.attach(reader_);
}

RobotJointsReader::~RobotJointsReader() {
  try {
    waitset_.detach(reader_);
  } catch (const Error&) {
    // Deleting the reader detaches it anyway.
  }
}

std::vector<RobotJoints> RobotJointsReader::take(std::chrono::nanoseconds timeout) {
  if (timeout.count() > 0) waitset_.wait(timeout);
  std::vector<RobotJoints> samples;
  const std::int64_t now_ns = wall_clock_ns();
  reader_.take_all([&](const void* sample, const dds_sample_info_t&) {
    const auto& msg = *static_cast<const cellmap_msg_RobotJoints*>(sample);
    if (msg.cell != nullptr && cell_ != msg.cell) return;
    try {
      RobotJoints joints = wire::from_wire(msg);
      check_limits(joints, limits_, now_ns);
      samples.push_back(in_robot_order(std::move(joints), joint_names_));
    } catch (const Error& e) {
      ++rejected_;
      if (on_refused_) on_refused_(e.what());
    }
  });
  return samples;
}

}  // namespace cellmap::transport
