// SPDX-License-Identifier: Apache-2.0
#pragma once
// Depth cameras as cellmapd's sensors: frames from each camera's DepthSource, posed in the cell (fixed, or
// on the tool through the robot's poses at the frame's stamp) with the robot as it stood then.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/frame/joint_buffer.hpp"
#include "cellmap/frame/pose_buffer.hpp"
#include "cellmap/ros2/joint_state_reader.hpp"
#include "cellmap/sensor/depth_source.hpp"
#include "cellmap/transport/robot_joints.hpp"
#include "cellmap/transport/robot_state.hpp"
#include "daemon_config.hpp"

namespace cellmap::daemon {

/// How far from the daemon's clock a robot pose's or joint sample's stamp may be. Frames are matched to
/// poses within `pose_tolerance` (0.05 s by default), so a controller whose clock is off by more is useless
/// anyway.
inline constexpr std::chrono::seconds kMaxPoseSkew{5};

/// The live robot of a cell with cameras: with a robot model, its joint samples (cellmap/robot_joints) in a
/// JointBuffer (every link's pose and the payload at any frame's stamp); without, its tool poses
/// (cellmap/robot_state) in a PoseBuffer. Samples outside the cell or stamped more than kMaxPoseSkew from now
/// are refused like malformed ones: counted, passed to `on_refused`, never used. pump() is for one thread;
/// the buffers may be read from any.
class RobotInput final {
 public:
  /// @param tolerance     seconds from a frame to each bracketing sample (the cameras' pose_tolerance)
  /// @param joint_states  a ROS 2 sensor_msgs/msg/JointState topic to take the robot model's joints from
  ///                      instead of cellmap/robot_joints; "" = cellmap/robot_joints
  /// @throws Error if the reader cannot be created, or joint_states is given without a robot model.
  RobotInput(const std::optional<Robot>& robot, double tolerance, const dds::Participant& participant,
             const std::string& cell, const std::string& joint_states, transport::OnRefused on_refused);

  /// Waits up to `timeout` for samples and moves those that arrived into the buffer.
  void pump(std::chrono::milliseconds timeout);

  /// The joint buffer (with a robot model), else nullptr.
  [[nodiscard]] const JointBuffer* joints() const { return joints_ ? &*joints_ : nullptr; }
  /// The tool-pose buffer (without a robot model), else nullptr.
  [[nodiscard]] const PoseBuffer* poses() const { return poses_ ? &*poses_ : nullptr; }
  /// Samples received and those refused (malformed on the wire or refused by the buffer). Thread-safe.
  [[nodiscard]] std::uint64_t received() const { return received_; }
  [[nodiscard]] std::uint64_t rejected() const;
  /// "joint samples" or "robot poses", for log lines.
  [[nodiscard]] const char* what() const { return joints_ ? "joint samples" : "robot poses"; }

 private:
  transport::OnRefused on_refused_;
  std::optional<JointBuffer> joints_;
  std::optional<PoseBuffer> poses_;
  std::optional<transport::RobotJointsReader> joint_reader_;
  std::optional<ros2::JointStateReader> joint_state_reader_;
  std::optional<transport::RobotStateReader> pose_reader_;
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> refused_{0};  // well-formed on the wire but refused by the buffer
};

/// The source of `config`: a ROS 2 topic's (pointcloud2, laserscan) on `participant`, its samples refused
/// to `on_refused`; else the camera's own (make_depth_source). @throws Error as the source's constructor.
[[nodiscard]] std::unique_ptr<DepthSource> make_source(const SourceConfig& config,
                                                       const dds::Participant& participant,
                                                       transport::OnRefused on_refused);

/// One camera: its frames posed in the cell frame (X_CS = X_CS fixed, or X_CE(stamp) · X_ES on the tool)
/// with the robot at the frame's stamp when the cell has a robot model. A frame whose pose (or robot) is not
/// known within the tolerance is dropped and counted; one newer than every sample waits up to `pose_wait`
/// for it. A replay poses its tool frames from its own recording (no robot: its frames are not self
/// filtered). Not thread-safe: one camera thread owns it.
class CameraInput final {
 public:
  /// @param source  the camera's frames (make_source)
  /// @param robot   the cell's live robot (must outlive this), or nullptr (replay)
  /// @throws Error if the grouping settings are invalid.
  CameraInput(const SourceConfig& config, std::unique_ptr<DepthSource> source, const RobotInput* robot);

  /// Opens the camera; a missing device is not an error (the status says disconnected and it is retried).
  /// A replay's recorded poses are loaded into its pose buffer.
  SourceStatus open();
  /// One turn of the camera loop: waits up to `timeout` for a frame and returns the frames posed in this
  /// turn, oldest first. While the camera is not streaming, frames still waiting are posed if they can be
  /// and dropped otherwise. Never blocks much longer than `timeout`.
  [[nodiscard]] std::vector<SweepFrame> step(std::chrono::milliseconds timeout);

  [[nodiscard]] SourceStatus status() const { return source_->status(); }
  [[nodiscard]] const std::string& name() const { return source_->name(); }
  /// Frames dropped for want of a pose or robot state.
  [[nodiscard]] std::uint64_t dropped_frames() const { return dropped_; }
  /// Replay: recorded poses loaded.
  [[nodiscard]] std::size_t recorded_poses() const { return recorded_ ? recorded_->size() : 0; }

 private:
  struct Waiting {
    Frame frame;
    double arrived = 0.0;
  };
  // Poses `frame` (and the robot with it) if its stamp is covered.
  PoseLookup locate(SweepFrame& frame) const;
  void pose_waiting(double give_up_before, std::vector<SweepFrame>& posed);

  SourceConfig config_;
  std::unique_ptr<DepthSource> source_;
  const RobotInput* robot_;
  std::optional<PoseBuffer> recorded_;  // replay only
  std::deque<Waiting> waiting_;
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace cellmap::daemon
