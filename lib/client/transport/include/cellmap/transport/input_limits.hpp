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

/// The most any sample on a cellmap topic may carry, checked on receipt by every reader (a sample beyond is
/// refused with the count in its reason): far above any real cell, low enough that no writer makes a
/// reader hold or loop over more. A snapshot of 100 000 boxes is 6.4 MB on the wire.
inline constexpr std::size_t kMaxBoxes = 100'000;   ///< a snapshot's boxes; each list of a delta
inline constexpr std::size_t kMaxSensors = 64;      ///< a status report's sensors; a sensors layer's views
inline constexpr std::size_t kMaxJoints = 64;       ///< a joint sample's names and positions
inline constexpr std::size_t kMaxRegions = 10'000;  ///< a change-region layer's regions
inline constexpr std::size_t kMaxVoxelRuns = 2'000'000;      ///< a voxel layer's runs (32 MB)
inline constexpr std::size_t kMaxShapes = 1'024;             ///< a robot layer's shapes
inline constexpr std::size_t kMaxMeshValues = 3'000'000;     ///< a mesh's vertex coordinates, and its indices
inline constexpr std::size_t kMaxOutlineValues = 3 * 1'024;  ///< a sensor view's outline coordinates
/// The largest serialized sample Cyclone DDS forwards in either direction in cellmap's processes
/// (its Internal/MaxSampleSize, set when a process first joins a domain; a CYCLONEDDS_URI that sets it
/// wins): room for the largest ROS 2 cloud accepted (ros2::kMaxCloudPoints, 16 million points) at 16 bytes
/// a point, and far more than any cellmap sample. Larger samples are dropped by Cyclone with a warning
/// before they are reassembled, so no writer makes a reader allocate more (Cyclone's default is 2 GB).
inline constexpr std::size_t kMaxSampleBytes = 256u << 20;

/// @throws Error "<where>: <count> <what>, more than the <limit> a sample may carry" when count > limit.
void require_at_most(std::size_t count, std::size_t limit, const std::string& what, const std::string& where);

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
