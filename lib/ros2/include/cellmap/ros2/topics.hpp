// SPDX-License-Identifier: Apache-2.0
#pragma once
// ROS 2's conventions on DDS, as rmw_cyclonedds and rmw_fastrtps apply them: ROS topic `/a/b` is DDS topic
// `rt/a/b` in the default partition; type `pkg/msg/Type` is DDS type `pkg::msg::dds_::Type_` (idl/ros2);
// ROS's default QoS is RELIABLE, VOLATILE, KEEP_LAST 10.

#include <string>

namespace cellmap::ros2 {

/// The DDS topic of a fully qualified ROS 2 topic name: "/camera/depth/points" → "rt/camera/depth/points".
/// @throws Error "'<name>' is not a ROS 2 topic name: <reason>" unless the name starts with '/', has only
/// letters, digits, '_' and '/', no empty token ("//", a trailing '/') and no token starting with a digit.
[[nodiscard]] std::string dds_topic(const std::string& ros_topic);

/// Whether a reader takes a publisher's samples reliably. A BEST_EFFORT reader matches writers of either
/// kind, so sensor inputs default to it: most ROS 2 camera and lidar drivers publish BEST_EFFORT
/// (rclcpp's SensorDataQoS), which a RELIABLE reader never matches.
enum class Reliability { kBestEffort, kReliable };
/// "best_effort" | "reliable".
[[nodiscard]] const char* to_string(Reliability reliability);

}  // namespace cellmap::ros2
