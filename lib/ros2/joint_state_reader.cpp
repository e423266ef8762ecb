// SPDX-License-Identifier: Apache-2.0
#include "cellmap/ros2/joint_state_reader.hpp"

#include <cstdlib>
#include <utility>

#include "cellmap/common/error.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "cellmap/ros2/joint_state.hpp"
#include "cellmap/ros2/topics.hpp"
#include "cellmap/ros2/type_hash.hpp"
#include "wire_views.hpp"

namespace cellmap::ros2 {
namespace {

// 1 s of a 250 Hz controller: the camera loop takes samples every 100 ms at the latest.
constexpr std::uint32_t kJointReaderDepth = 256;

dds::Qos reader_qos() {
  dds::Qos qos = dds::Qos::make(false, kJointReaderDepth);
  qos.best_effort().user_data(type_hash_user_data("sensor_msgs/msg/JointState"));
  return qos;
}

}  // namespace

JointStateReader::JointStateReader(const dds::Participant& participant, std::string topic, std::string cell,
                                   std::vector<std::string> joint_names,
                                   std::chrono::nanoseconds max_stamp_skew, transport::OnRefused on_refused)
    : topic_name_(std::move(topic)),
      cell_(std::move(cell)),
      joint_names_(std::move(joint_names)),
      max_stamp_skew_(max_stamp_skew),
      on_refused_(std::move(on_refused)),
      topic_(participant, &sensor_msgs_msg_dds__JointState__desc, dds_topic(topic_name_)),
      reader_(participant, topic_, reader_qos()),
      waitset_(participant) {
  if (joint_names_.empty()) throw Error(topic_name_ + " reader: the robot has no joints");
  waitset_.attach(reader_);
}

JointStateReader::~JointStateReader() {
  try {
    waitset_.detach(reader_);
  } catch (const Error&) {
    // Deleting the reader detaches it anyway.
  }
}

std::vector<transport::RobotJoints> JointStateReader::take(std::chrono::nanoseconds timeout) {
  if (timeout.count() > 0) waitset_.wait(timeout);
  std::vector<transport::RobotJoints> samples;
  const std::int64_t now_ns = wall_clock_ns();
  reader_.take_all([&](const void* sample, const dds_sample_info_t&) {
    const auto& msg = *static_cast<const sensor_msgs_msg_dds__JointState_*>(sample);
    try {
      const auto& stamp = msg.header.stamp;
      if (stamp.nanosec >= 1'000'000'000u) throw Error("header.stamp.nanosec is not below 1e9");
      transport::RobotJoints joints;
      joints.cell = cell_;
      joints.stamp_ns = std::int64_t{stamp.sec} * 1'000'000'000 + stamp.nanosec;
      if (max_stamp_skew_.count() > 0 && std::abs(joints.stamp_ns - now_ns) > max_stamp_skew_.count())
        throw Error("stamped " + std::to_string(double(joints.stamp_ns - now_ns) * 1e-9) + " s from now");
      joints.positions = in_robot_order(names_of(msg), positions_of(msg), joint_names_);
      joints.names = joint_names_;
      samples.push_back(std::move(joints));
    } catch (const Error& e) {
      ++rejected_;
      if (on_refused_) on_refused_(topic_name_ + " (sensor_msgs/msg/JointState): " + e.what());
    }
  });
  return samples;
}

}  // namespace cellmap::ros2
