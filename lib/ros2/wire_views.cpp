// SPDX-License-Identifier: Apache-2.0
#include "wire_views.hpp"

namespace cellmap::ros2 {

PointCloud2View view_of(const sensor_msgs_msg_dds__PointCloud2_& msg) {
  PointCloud2View view{msg.height,       msg.width,       {}, msg.is_bigendian, msg.point_step, msg.row_step,
                       msg.data._buffer, msg.data._length};
  view.fields.reserve(msg.fields._length);
  for (std::uint32_t i = 0; i < msg.fields._length; ++i) {
    const auto& f = msg.fields._buffer[i];
    view.fields.push_back({f.name ? f.name : "", f.offset, f.datatype, f.count});
  }
  return view;
}

LaserScanView view_of(const sensor_msgs_msg_dds__LaserScan_& msg) {
  return {msg.angle_min, msg.angle_max,      msg.angle_increment, msg.range_min,
          msg.range_max, msg.ranges._buffer, msg.ranges._length};
}

std::vector<std::string> names_of(const sensor_msgs_msg_dds__JointState_& msg) {
  std::vector<std::string> names;
  names.reserve(msg.name._length);
  for (std::uint32_t i = 0; i < msg.name._length; ++i)
    names.emplace_back(msg.name._buffer[i] ? msg.name._buffer[i] : "");
  return names;
}

std::vector<double> positions_of(const sensor_msgs_msg_dds__JointState_& msg) {
  return {msg.position._buffer, msg.position._buffer + msg.position._length};
}

}  // namespace cellmap::ros2
