// SPDX-License-Identifier: Apache-2.0
// ROS 2 sensor samples as received from any ROS 2 node: the first byte picks the type (PointCloud2,
// LaserScan, JointState), the rest is the serialized payload (4-byte encapsulation header, then CDR). The
// payload goes through Cyclone's receive steps (cdr_sample.hpp), then through what cellmapd's ROS 2 inputs
// do with it (lib/ros2's views, the conversion to points, the robot's joint order) and what the daemon does
// with the result: a cloud's points posed into the cell, a scan's beams too, joint positions into the SCARA
// arm's JointBuffer.
#include <optional>

#include "cdr_sample.hpp"
#include "cellmap/frame/joint_buffer.hpp"
#include "cellmap/ros2/joint_state.hpp"
#include "cellmap/urdf/urdf_model.hpp"
#include "fuzz_support.hpp"
#include "wire_views.hpp"

namespace {

using namespace cellmap;

void points_of(const sensor_msgs_msg_dds__PointCloud2_& msg) {
  const Cloud cloud = ros2::to_points(ros2::view_of(msg));
  for (const pcl::PointXYZ& p : cloud) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();  // must be left out
  }
}

void points_of(const sensor_msgs_msg_dds__LaserScan_& msg) {
  const ros2::ScanPoints scan = ros2::to_points(ros2::view_of(msg));
  if (scan.points_S.size() + scan.no_return_S.size() > msg.ranges._length) std::abort();
}

// The SCARA arm of config/scenes/ (four joints), as a daemon with ros2.joint_states reads joints for it.
void push_joints(const sensor_msgs_msg_dds__JointState_& msg) {
  static const Robot robot = UrdfModel::load(CELLMAP_SOURCE_DIR "/config/scenes/scara.urdf").chain("flange");
  const std::vector<double> q =
      ros2::in_robot_order(ros2::names_of(msg), ros2::positions_of(msg), robot.joint_names());
  JointBuffer buffer(robot, 0.01, 16);
  buffer.push({1.0, Eigen::Map<const Eigen::VectorXd>(q.data(), Eigen::Index(q.size())), std::nullopt});
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const dds_topic_descriptor_t* const kTypes[] = {&sensor_msgs_msg_dds__PointCloud2__desc,
                                                         &sensor_msgs_msg_dds__LaserScan__desc,
                                                         &sensor_msgs_msg_dds__JointState__desc};
  const std::size_t kind = data[0] % std::size(kTypes);
  fuzz::Decoded sample(*kTypes[kind]);
  if (!sample.decode(data + 1, size - 1)) return 0;
  fuzz::accept_or_refuse([&] {
    switch (kind) {
      case 0:
        return points_of(sample.as<sensor_msgs_msg_dds__PointCloud2_>());
      case 1:
        return points_of(sample.as<sensor_msgs_msg_dds__LaserScan_>());
      default:
        return push_joints(sample.as<sensor_msgs_msg_dds__JointState_>());
    }
  });
  return 0;
}
