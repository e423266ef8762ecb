// SPDX-License-Identifier: Apache-2.0
#pragma once
// ROS 2 sensor drivers as cellmap depth sources: sensor_msgs/msg/PointCloud2 (depth cameras, 3D lidars) and
// sensor_msgs/msg/LaserScan (2D lidars) read straight off DDS, no ROS installed. The frames they give are
// posed by the daemon like any camera's (fixed in the cell, or on the tool at the frame's stamp).

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "cellmap/ros2/topics.hpp"
#include "cellmap/sensor/depth_source.hpp"
#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/input_limits.hpp"

namespace cellmap::ros2 {

/// Where a ROS 2 sensor's samples come from and which of them are taken.
struct TopicInput final {
  std::string topic;     ///< ROS 2 topic, e.g. "/camera/depth/points"
  std::string frame_id;  ///< the header.frame_id its samples carry; a sample in another frame is refused
  Reliability reliability = Reliability::kBestEffort;
  /// Seconds without a sample after which the source reports itself disconnected.
  double frame_timeout = 2.0;
  /// PointCloud2: points nearer than this to the frame's origin, metres, are no return (drivers that keep a
  /// pixel without depth as (0, 0, 0), e.g. an ordered RealSense cloud). LaserScan uses the scan's range_min.
  double min_range = 0.05;
  /// Samples stamped farther than this from now (CLOCK_REALTIME) are refused; zero: not checked.
  std::chrono::nanoseconds max_stamp_skew = std::chrono::seconds(5);
};

/// Frames from the sensor_msgs/msg/PointCloud2 samples on `input.topic`: the points (ros2::to_points) in
/// the sensor frame S = the cloud's header frame, stamped with header.stamp (seconds, CLOCK_REALTIME). A
/// sample that cannot be read, is in another frame or stamped too far from now is refused: counted in
/// rejected(), passed to `on_refused` with one line naming the topic, never a frame. The status is
/// disconnected until the first frame and after frame_timeout without one. `participant` must outlive the
/// source. Not thread-safe (one camera thread drives it, as every DepthSource).
/// @throws Error if the topic name is not a ROS 2 one, frame_id is empty or the reader cannot be created.
[[nodiscard]] std::unique_ptr<DepthSource> make_point_cloud2_source(const dds::Participant& participant,
                                                                    std::string name, TopicInput input,
                                                                    transport::OnRefused on_refused);

/// As make_point_cloud2_source, for sensor_msgs/msg/LaserScan: each scan one frame with its returns as
/// points_S, the far ends of its beams without a return as Frame::no_return_S and its fan as the field of
/// view. The scan is taken as one instant (header.stamp): at a gantry's speeds (< 1 m/s) a 40 ms scan
/// moves the scanner under 4 cm, about two voxels.
[[nodiscard]] std::unique_ptr<DepthSource> make_laser_scan_source(const dds::Participant& participant,
                                                                  std::string name, TopicInput input,
                                                                  transport::OnRefused on_refused);

}  // namespace cellmap::ros2
