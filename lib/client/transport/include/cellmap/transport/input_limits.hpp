// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a daemon accepts from outside over DDS besides what the wire format already enforces (every number
// finite, unit quaternions, known enum values, names present): positions inside the cell, boxes that fit in
// it, robot poses and joint states stamped near now, payloads that fit in the cell. A sample outside is
// refused: counted by its reader, never returned.

#include <Eigen/Geometry>

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "cellmap/transport/messages.hpp"

namespace cellmap::transport {

/// The limit for cells that state no bounds (cameras): no cell reaches farther than this from its origin
/// along any axis, metres.
inline constexpr double kMaxCellCoordinate = 100.0;
/// The longest obstacle name a scene edit may carry, bytes.
inline constexpr std::size_t kMaxNameLength = 128;

struct InputLimits final {
  /// Scene-edit centres and tool positions p_C must lie inside (cell frame, metres); an added box's half
  /// extents must each be at most half the cell's largest side.
  Eigen::AlignedBox3d cell{Eigen::Vector3d::Constant(-kMaxCellCoordinate),
                           Eigen::Vector3d::Constant(kMaxCellCoordinate)};
  /// Robot poses stamped farther than this from now are refused; zero: stamps are not checked.
  std::chrono::nanoseconds max_stamp_skew{0};
};

/// Called by a reader for each sample it refuses, with the reason (an Error's one-line message).
using OnRefused = std::function<void(const std::string& reason)>;

/// @throws Error "cellmap/sim/scene_edits '<name>': <field>: <reason>" if the edit breaks a limit: name
/// longer than kMaxNameLength; add-box or move: centre outside the cell; add-box: a half extent not positive
/// or over half the cell's largest side, |yaw| over 2π. Remove uses only the name.
void check_limits(const SceneEdit& edit, const InputLimits& limits);
/// @throws Error "cellmap/robot_state '<cell>' at <stamp>: <field>: <reason>" if the tool position is outside
/// the cell or the stamp is farther than max_stamp_skew from `now_ns` (ns since the Unix epoch).
void check_limits(const RobotState& state, const InputLimits& limits, std::int64_t now_ns);
/// @throws Error "cellmap/robot_joints '<cell>' at <stamp>: <field>: <reason>" if the stamp is farther than
/// max_stamp_skew from `now_ns`, or the payload's centre is farther from the tool than the cell's largest
/// side or a half extent is over half of it.
void check_limits(const RobotJoints& joints, const InputLimits& limits, std::int64_t now_ns);

}  // namespace cellmap::transport
