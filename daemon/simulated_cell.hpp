// SPDX-License-Identifier: Apache-2.0
#pragma once
// The simulated sensors of cellmapd: the simulator's scene seen by the configured sensors of the scene,
// editable between sweeps through cellmap/sim/scene_edits. With a scene motion the robot moves all the time
// and its controller's joint samples pose the tool sensors and the robot, as a live cell's would.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/frame/joint_buffer.hpp"
#include "cellmap/sim/simulator.hpp"
#include "cellmap/transport/messages.hpp"
#include "daemon_config.hpp"

namespace cellmap::daemon {

/// `config` with `pipeline.unknown.workspace` taken from its simulated scene's `workspace` when the config
/// names none (a simulated cell's scene knows where unknown space matters). A scene that does not load leaves
/// the config as it is: the simulated cell reports it when it loads the scene.
[[nodiscard]] DaemonConfig with_scene_workspace(DaemonConfig config);

/// Renders sweeps of the configured scene and applies scene edits between them. Not thread-safe: the
/// acquisition thread owns it.
class SimulatedCell final {
 public:
  /// `sources`: the sim entries (one scene, their sensors); `robot`: the daemon's robot model (nullopt: the
  /// scene's).
  /// @throws Error naming the scene file or the sensor when the scene does not load or has no such sensor,
  /// or if the robot model's joints are not the scene robot's.
  SimulatedCell(const std::vector<SourceConfig>& sources, const std::optional<Robot>& robot);

  /// The next sweep, in the cell frame, fresh noise each call. With a scene motion: every configured
  /// sensor's frames in [start, start + duration) of the motion's time, tool sensors posed (and the robot
  /// given to each frame) from the controller's joint samples interpolated at the frame's stamp through the
  /// daemon's robot model; a frame no joint sample brackets within the tolerance is dropped and counted.
  /// Without: one pass along the scene's sweep plan per sensor (duration unused), the robot at each stop.
  [[nodiscard]] FrameSweep next_sweep(double start, double duration);
  /// Applies an edit received over DDS; returns the obstacle's name. @throws Error if the edit is invalid
  /// (unknown name, taken name, bad size); the scene is then unchanged.
  std::string apply(const transport::SceneEdit& edit);

  [[nodiscard]] const sim::Scene& scene() const { return simulator_.scene(); }
  /// The robot model the frames are posed with.
  [[nodiscard]] const Robot& robot() const { return joints_.robot(); }
  /// "post, wrist".
  [[nodiscard]] std::string sensor_names() const;
  /// Seconds of motion one sweep covers when sweeps run as fast as processed: one pass of the sweep plan.
  [[nodiscard]] double pass_duration() const;
  /// Frames dropped for want of a joint sample.
  [[nodiscard]] std::uint64_t dropped_frames() const { return dropped_; }

 private:
  [[nodiscard]] FrameSweep moving_sweep(double start, double duration);
  [[nodiscard]] FrameSweep stop_sweep(double start);

  sim::Simulator simulator_;
  std::vector<int> sensors_;
  std::vector<double> no_return_ranges_;  // per scene sensor (index as the scene's), from the sources
  JointBuffer joints_;
  std::uint64_t sweep_index_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace cellmap::daemon
