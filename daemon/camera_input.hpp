#pragma once
// A depth camera on the robot as cellmapd's sweep source: frames from its DepthSource, the tool poses from
// the replay recording or the cellmap/robot_state topic, grouped into sweeps by the SweepAssembler.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/frame/pose_buffer.hpp"
#include "cellmap/sensor/depth_source.hpp"
#include "cellmap/sweep/sweep_assembler.hpp"
#include "cellmap/transport/robot_state.hpp"
#include "daemon_config.hpp"

namespace cellmap::daemon {

/// How far from the daemon's clock a robot pose's stamp may be. Frames are matched to poses within
/// `source.pose_tolerance` (0.05 s by default), so a controller whose clock is off by more is useless anyway.
inline constexpr std::chrono::seconds kMaxPoseSkew{5};

/// Not thread-safe: the acquisition thread owns it. `participant` must outlive it.
class CameraInput final {
 public:
  /// Live cameras read the cell's robot poses; a pose outside the cell (transport::kMaxCellCoordinate) or
  /// stamped more than kMaxPoseSkew from now is refused like a malformed one: counted, passed to
  /// `on_refused`, never used.
  /// @throws Error if the camera settings are invalid (the source's constructor) or the robot-state reader
  /// cannot be created.
  CameraInput(const SourceConfig& config, const dds::Participant& participant, const std::string& cell,
              transport::OnRefused on_refused = {});

  /// Opens the camera; a missing device is not an error (the status says disconnected and it is retried).
  /// A replay's recorded poses are loaded into the pose buffer.
  SourceStatus open();
  /// One turn of the acquisition loop: takes the robot poses that arrived, waits up to `timeout` for a frame
  /// and returns the sweeps completed. While the camera is not streaming (lost, ended, failed) the open sweep
  /// is closed with the frames it has. Never blocks much longer than `timeout`.
  [[nodiscard]] std::vector<Sweep> step(std::chrono::milliseconds timeout);

  [[nodiscard]] SourceStatus status() const { return source_->status(); }
  [[nodiscard]] const std::string& name() const { return source_->name(); }
  /// Frames dropped for want of a pose.
  [[nodiscard]] std::uint64_t dropped_frames() const { return assembler_.dropped(); }
  /// Robot poses received (replay: recorded) so far, and those refused as malformed.
  [[nodiscard]] std::uint64_t poses_received() const { return poses_received_; }
  [[nodiscard]] std::uint64_t poses_rejected() const;

 private:
  std::unique_ptr<DepthSource> source_;
  PoseBuffer poses_;
  SweepAssembler assembler_;
  transport::OnRefused on_refused_;
  std::optional<transport::RobotStateReader> robot_;  // live cameras only
  std::uint64_t poses_received_ = 0;
  std::uint64_t poses_refused_ = 0;  // well-formed on the wire but refused by the pose buffer
};

}  // namespace cellmap::daemon
