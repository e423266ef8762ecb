// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmap/robot_joints: the robot controller tells cellmapd its joint positions and what the tool holds, so
// the daemon knows where every link, every sensor on the robot and the robot itself in its sensors' view are.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/input_limits.hpp"
#include "cellmap/transport/messages.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::transport {

/// Sends joint states (the robot controller's side, or a test). `participant` must outlive it. Thread-safe as
/// Cyclone's writes are.
class RobotJointsWriter final {
 public:
  /// Writes joint states of `cell` only, into its partition. @throws Error if `cell` is empty or kEveryCell.
  RobotJointsWriter(const dds::Participant& participant, std::string cell);
  /// True once at least one robot-joints reader (a daemon) matched, false on timeout.
  bool wait_for_reader(std::chrono::nanoseconds timeout) const;
  /// @throws Error naming the topic and field if the cell is empty or not the writer's, names are given but their count is not
  /// the positions' count, a number is not finite, a payload half extent is negative or its rotation is not
  /// orthonormal, or the write fails.
  void write(const RobotJoints& joints) const;
  /// True once every matched reader acknowledged everything written, false on timeout.
  bool wait_for_acks(std::chrono::nanoseconds timeout) const;

 private:
  std::string cell_;
  dds::Topic topic_;
  dds::Writer writer_;
};

/// `joints` with names = `joint_names` and positions in that order (what RobotJointsReader::take returns).
/// @throws Error "cellmap/robot_joints '<cell>' at <stamp>: <reason>" if the names are not exactly the
/// robot's joints (unknown or repeated) or the positions' count is not the robot's.
[[nodiscard]] RobotJoints in_robot_order(RobotJoints joints, const std::vector<std::string>& joint_names);

/// Receives joint states for one cell and one robot (cellmapd's side). `participant` must outlive it. Not
/// thread-safe.
class RobotJointsReader final {
 public:
  /// @param cell         only this cell's samples are returned; others are skipped (not counted as rejected)
  /// @param joint_names  the robot's joints in its order (Robot::joint_names())
  /// @param limits       samples outside them are refused (input_limits.hpp; stamps against CLOCK_REALTIME)
  /// @param on_refused   called with the reason of each refused sample, from take()
  /// @throws Error if joint_names is empty or holds a name twice.
  RobotJointsReader(const dds::Participant& participant, std::string cell,
                    std::vector<std::string> joint_names, InputLimits limits = {}, OnRefused on_refused = {});
  ~RobotJointsReader();
  RobotJointsReader(const RobotJointsReader&) = delete;
  RobotJointsReader& operator=(const RobotJointsReader&) = delete;

  /// Waits up to `timeout` for data (zero: just looks) and returns the samples received, oldest first, with
  /// names = the robot's joint names and positions in that order. Refused (skipped, counted in rejected() and
  /// passed to on_refused): an empty cell, non-finite numbers, a bad payload, samples outside the limits,
  /// names that are not exactly the robot's joints (unknown, missing or repeated), or a count that is not the
  /// robot's.
  std::vector<RobotJoints> take(std::chrono::nanoseconds timeout = std::chrono::nanoseconds(0));
  [[nodiscard]] std::uint64_t rejected() const { return rejected_; }

 private:
  std::string cell_;
  std::vector<std::string> joint_names_;
  InputLimits limits_;
  OnRefused on_refused_;
  dds::Topic topic_;
  dds::Reader reader_;
  dds::WaitSet waitset_;
  std::uint64_t rejected_ = 0;
};

}  // namespace cellmap::transport
