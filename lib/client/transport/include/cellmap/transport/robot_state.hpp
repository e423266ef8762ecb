// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmap/robot_state: the robot controller tells cellmapd where the tool is, so camera frames get their
// pose.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/input_limits.hpp"
#include "cellmap/transport/messages.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::transport {

/// Sends tool poses (the robot controller's side, or a test). `participant` must outlive it. Thread-safe as
/// Cyclone's writes are.
class RobotStateWriter final {
 public:
  /// Writes poses of `cell` only, into its partition. @throws Error if `cell` is empty or kEveryCell.
  RobotStateWriter(const dds::Participant& participant, std::string cell);
  /// True once at least one robot-state reader (a daemon) matched, false on timeout.
  bool wait_for_reader(std::chrono::nanoseconds timeout) const;
  /// The rotation is sent as a quaternion of X_CE.linear(), which must be a rotation matrix: a scaled one
  /// is sent as a non-unit quaternion, which every reader rejects and counts.
  /// @throws Error if the cell is not the writer's, the pose is not finite, or the write fails.
  void write(const RobotState& state) const;
  /// True once every matched reader acknowledged everything written, false on timeout.
  bool wait_for_acks(std::chrono::nanoseconds timeout) const;

 private:
  std::string cell_;
  dds::Topic topic_;
  dds::Writer writer_;
};

/// Receives tool poses for one cell (cellmapd's side). `participant` must outlive it. Not thread-safe.
class RobotStateReader final {
 public:
  /// @param cell       only this cell's poses are returned; others are skipped (not counted as rejected).
  /// @param limits     poses outside them are refused (input_limits.hpp; stamps against CLOCK_REALTIME)
  /// @param on_refused called with the reason of each refused pose, from take()
  RobotStateReader(const dds::Participant& participant, std::string cell, InputLimits limits = {},
                   OnRefused on_refused = {});
  ~RobotStateReader();
  RobotStateReader(const RobotStateReader&) = delete;
  RobotStateReader& operator=(const RobotStateReader&) = delete;
  /// Waits up to `timeout` for data (zero: just looks) and returns the poses received, oldest first.
  /// Malformed samples (empty cell, non-finite numbers, non-unit quaternion) and poses outside the limits are
  /// refused: skipped, counted in rejected() and passed to on_refused.
  std::vector<RobotState> take(std::chrono::nanoseconds timeout = std::chrono::nanoseconds(0));
  [[nodiscard]] std::uint64_t rejected() const { return rejected_; }

 private:
  std::string cell_;
  InputLimits limits_;
  OnRefused on_refused_;
  dds::Topic topic_;
  dds::Reader reader_;
  dds::WaitSet waitset_;
  std::uint64_t rejected_ = 0;
};

}  // namespace cellmap::transport
