// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmap's DDS topics and their QoS (the contract: docs/dds.md). Writers and readers both use these, so a
// reader never silently falls back to Cyclone's BEST_EFFORT/VOLATILE defaults.

#include <cstdint>
#include <map>
#include <string>

#include "cellmap/security/cell_setup.hpp"
#include "cellmap/transport/dds.hpp"

namespace cellmap::transport {

inline constexpr const char* kEnvironmentTopic = "cellmap/environment";
inline constexpr const char* kEnvironmentDeltaTopic = "cellmap/environment_delta";
inline constexpr const char* kStatusTopic = "cellmap/status";
inline constexpr const char* kSceneEditTopic = "cellmap/sim/scene_edits";
inline constexpr const char* kRobotStateTopic = "cellmap/robot_state";
inline constexpr const char* kVoxelLayerTopic = "cellmap/layer/voxels";
inline constexpr const char* kChangeRegionLayerTopic = "cellmap/layer/change_regions";
inline constexpr const char* kSensorLayerTopic = "cellmap/layer/sensors";
inline constexpr const char* kRobotLayerTopic = "cellmap/layer/robot";
inline constexpr const char* kRobotJointsTopic = "cellmap/robot_joints";

/// Each cell's traffic travels in a DDS partition of its own, "cellmap/<cell>": a reader of one cell is never
/// matched with another cell's writers, so their samples never reach it (keys alone would only sort them
/// into instances after they crossed the wire). kEveryCell in place of a cell id makes the pattern
/// "cellmap/*": a reader that follows every cell (a monitor, `cellmap echo`), or a scene-edit writer that
/// edits every simulating daemon.
inline constexpr const char* kEveryCell = "*";
inline constexpr const char* kPartitionPrefix = "cellmap/";

/// "cellmap/<cell>", or "cellmap/*" for kEveryCell.
/// @throws Error if the cell is empty or holds '*', '?' or '\\' (pattern characters) other than kEveryCell.
[[nodiscard]] std::string cell_partition(const std::string& cell);

/// `cell` when it names one cell. @throws Error "<what>: ..." if it is empty or kEveryCell.
[[nodiscard]] std::string one_cell(std::string cell, const std::string& what);

/// `qos` limited to the partition of `cell` (cell_partition).
[[nodiscard]] dds::Qos in_cell(dds::Qos qos, const std::string& cell);

/// What a program follows when no cell is given: with DDS Security on, the cell of its credentials (they
/// grant no other partition); without, kEveryCell.
[[nodiscard]] std::string default_cell(const dds::Participant& participant);

/// How many deltas per cell the writer keeps for late joiners unless configured otherwise.
inline constexpr std::uint32_t kDefaultDeltaDepth = 16;

/// cellmap/environment: RELIABLE, TRANSIENT_LOCAL, KEEP_LAST 1 (a late joiner gets the current snapshot).
[[nodiscard]] dds::Qos environment_qos();
/// cellmap/environment_delta: RELIABLE, TRANSIENT_LOCAL, KEEP_LAST `depth` (>= 1).
[[nodiscard]] dds::Qos environment_delta_qos(std::uint32_t depth);
/// cellmap/status: RELIABLE, TRANSIENT_LOCAL, KEEP_LAST 1 (a late joiner sees the last health report).
[[nodiscard]] dds::Qos status_qos();
/// cellmap/sim/scene_edits: RELIABLE, VOLATILE (a restarted daemon must not replay old edits), KEEP_ALL of at
/// most kMaxQueuedSceneEdits samples (ResourceLimits): a reader that holds that many untaken makes the
/// writers wait, so no writer fills the daemon's memory.
[[nodiscard]] dds::Qos scene_edit_qos();
inline constexpr std::uint32_t kMaxQueuedSceneEdits = 1024;
/// cellmap/robot_state: RELIABLE, VOLATILE (an old pose is no use to a restarted daemon), KEEP_LAST 256 per
/// cell (a second of a 250 Hz controller: a slow reader loses the oldest poses, the writer never blocks).
[[nodiscard]] dds::Qos robot_state_qos();
/// cellmap/robot_joints: as cellmap/robot_state (RELIABLE, VOLATILE, KEEP_LAST 256 per cell).
[[nodiscard]] dds::Qos robot_joints_qos();

/// cellmap/layer/*: RELIABLE, VOLATILE, KEEP_LAST 1 (a layer is the daemon's current view; a reader only
/// wants the newest, and the daemon writes it only while a reader is matched).
[[nodiscard]] dds::Qos layer_qos();

/// What each DDS Security role of `cell` may write and read, in the cell's partition only (`cellmap security
/// init` signs these into the permissions):
///   daemon   writes environment, delta, status, layers;  reads robot state and joints, scene edits (sim)
///   planner  writes nothing;                             reads environment, delta, status, layers (`view`)
///   robot    writes robot state and joints;              reads nothing
///   tool     writes scene edits (`inject`);              reads environment, delta, status (`echo`)
/// @throws Error if `cell` is not one valid cell id.
[[nodiscard]] std::map<security::Role, security::TopicGrants> role_grants(const std::string& cell);

}  // namespace cellmap::transport
