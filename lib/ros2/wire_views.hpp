// SPDX-License-Identifier: Apache-2.0
#pragma once
// The received ROS 2 samples (idlc's structs of idl/ros2) as lib/ros2's value views: internal to the stage
// (and its fuzz harness), so the public headers never name the generated types.

#include <string>
#include <vector>

#include "cellmap/ros2/laser_scan.hpp"
#include "cellmap/ros2/point_cloud2.hpp"
#include "sensor_msgs/msg/JointState.h"
#include "sensor_msgs/msg/LaserScan.h"
#include "sensor_msgs/msg/PointCloud2.h"

namespace cellmap::ros2 {

/// The cloud's fields and a view of its data (valid while `msg` is).
[[nodiscard]] PointCloud2View view_of(const sensor_msgs_msg_dds__PointCloud2_& msg);
/// The scan's angles, limits and a view of its ranges (valid while `msg` is).
[[nodiscard]] LaserScanView view_of(const sensor_msgs_msg_dds__LaserScan_& msg);
/// The joint names (a null string as "") and positions.
[[nodiscard]] std::vector<std::string> names_of(const sensor_msgs_msg_dds__JointState_& msg);
[[nodiscard]] std::vector<double> positions_of(const sensor_msgs_msg_dds__JointState_& msg);

}  // namespace cellmap::ros2
