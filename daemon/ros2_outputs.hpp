// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmapd's ROS 2 outputs (the `ros2` section): each published version to MoveIt's collision objects and
// RViz's markers, and the whole environment again to a move_group that joins later.

#include <optional>
#include <string>

#include "cellmap/ros2/environment_writers.hpp"
#include "daemon_config.hpp"

namespace cellmap::daemon {

/// The enabled outputs of `config` (none: every call does nothing). A failed write is logged (at most once
/// per reason in a row) and never reaches the caller: cellmap's own subscribers must not wait for ROS.
/// Thread-safe.
class Ros2Outputs final {
 public:
  /// `participant` must outlive this. @throws Error if a writer cannot be created (a bad topic name).
  Ros2Outputs(const Ros2Config& config, const dds::Participant& participant);
  /// After each version went out on cellmap's own topics.
  void publish(const Environment& env, const EnvironmentDelta& delta);
  /// Sends the current environment to MoveIt readers that matched since the last call; call often (the
  /// daemon: every 200 ms).
  void serve_new_readers();
  /// "MoveIt collision objects on /collision_object (frame world, unknown space too), RViz markers on
  /// /cellmap/markers (frame world, obstacles only)", or "" when none is enabled; for the start log line.
  [[nodiscard]] std::string describe() const;

 private:
  void report(const char* what, const Error& e);
  std::optional<ros2::CollisionObjectWriter> collision_objects_;
  std::optional<ros2::MarkerWriter> markers_;
  std::string description_;
  std::mutex mutex_;  // guards last_fault_
  std::string last_fault_;
};

}  // namespace cellmap::daemon
