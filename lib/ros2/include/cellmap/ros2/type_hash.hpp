// SPDX-License-Identifier: Apache-2.0
#pragma once
// REP 2011 type hashes of the ROS 2 message types cellmap speaks (idl/ros2). ROS 2 Jazzy's RMWs put
// "typehash=RIHS01_<hex>;" in the USER_DATA QoS of every writer and reader, which is how `ros2 topic info -v`
// shows an endpoint's type hash; with these, cellmap's endpoints carry the same. The hashes are computed at
// build time from idl/ros2 (idl/ros2/ros2_idl.py), the one definition of these types.

#include <string>
#include <string_view>

namespace cellmap::ros2 {

/// The type hash of ROS 2 message type `ros_type` ("sensor_msgs/msg/PointCloud2"): "RIHS01_" and 64 lowercase
/// hex digits, equal to the one ROS 2 Jazzy computes for it.
/// @throws Error naming `ros_type` if idl/ros2 does not define that type.
[[nodiscard]] std::string type_hash(std::string_view ros_type);

/// The USER_DATA text of a ROS 2 Jazzy endpoint of `ros_type`: "typehash=RIHS01_<hex>;".
/// @throws Error naming `ros_type` if idl/ros2 does not define that type.
[[nodiscard]] std::string type_hash_user_data(std::string_view ros_type);

}  // namespace cellmap::ros2
