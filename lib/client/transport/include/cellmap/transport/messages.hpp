// SPDX-License-Identifier: Apache-2.0
#pragma once
// Value types for the status, scene-edit, robot-state and robot-joints topics (the environment ones are
// cellmap::Environment and cellmap::EnvironmentDelta). The DDS wire types (idl/cellmap.idl) stay inside
// lib/client/transport.

#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/robot/joint_state.hpp"

namespace cellmap::transport {

struct SensorStatus final {
  std::string name;
  std::string state;  ///< "starting", "streaming", or the source state and reason ("disconnected: ...")
};

/// cellmap/status: one cell daemon's health.
struct CellStatus final {
  std::string cell;
  std::string state;  ///< "starting", "running", "degraded" or "stopped"
  std::vector<SensorStatus> sensors;
  std::int64_t last_sweep_ns = 0;  ///< end of the last sweep, ns since the Unix epoch; 0 before the first
  std::uint64_t sweeps = 0;
  std::uint64_t dropped_frames = 0;
  std::uint64_t boxes = 0;
  std::uint64_t version = 0;
  std::string reason;  ///< why the state is "degraded" (one line); empty otherwise
  /// scene edits and robot poses refused, never applied (input_limits.hpp)
  std::uint64_t refused_inputs = 0;
};

/// cellmap/sim/scene_edits: one edit of a simulated scene (what `cellmap inject` sends, what tests plant;
/// sim::apply applies it). The one scene-edit type.
struct SceneEdit final {
  enum class Kind { kAddBox, kRemove, kMove };
  std::string cell;  ///< empty: every simulated cell on the domain
  Kind kind = Kind::kAddBox;
  std::string name;  ///< the obstacle's name (add-box: empty lets the simulator choose one)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();        ///< p_CB, metres (add-box, move)
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();  ///< metres (add-box)
  double yaw = 0.0;                                        ///< about the cell's z axis, radians (add-box)

  [[nodiscard]] static SceneEdit add_box(std::string name, const Eigen::Vector3d& center,
                                         const Eigen::Vector3d& half_extents, double yaw = 0.0) {
    SceneEdit edit;
    edit.name = std::move(name);
    edit.center = center;
    edit.half_extents = half_extents;
    edit.yaw = yaw;
    return edit;
  }
  [[nodiscard]] static SceneEdit remove(std::string name) {
    SceneEdit edit;
    edit.kind = Kind::kRemove;
    edit.name = std::move(name);
    return edit;
  }
  [[nodiscard]] static SceneEdit move(std::string name, const Eigen::Vector3d& center) {
    SceneEdit edit;
    edit.kind = Kind::kMove;
    edit.name = std::move(name);
    edit.center = center;
    return edit;
  }
};

/// cellmap/robot_state: the robot's tool pose at one instant (what the robot controller sends).
struct RobotState final {
  std::string cell;                                        ///< must not be empty
  std::int64_t stamp_ns = 0;                               ///< ns since the Unix epoch (CLOCK_REALTIME)
  Eigen::Isometry3d X_CE = Eigen::Isometry3d::Identity();  ///< tool pose in the cell frame
};

/// cellmap/robot_joints: the robot's joint positions at one instant and what its tool holds.
struct RobotJoints final {
  std::string cell;                ///< must not be empty
  std::int64_t stamp_ns = 0;       ///< ns since the Unix epoch (CLOCK_REALTIME), the frames' clock
  std::vector<std::string> names;  ///< joint names; empty: positions are in the robot's joint order
  std::vector<double> positions;   ///< metres or radians, one per joint
  std::optional<Payload> payload;  ///< the box the tool holds, in the tool frame; none: the tool is empty

  /// The sample as a JointState (stamp in seconds) with q = positions as they are ordered here.
  [[nodiscard]] JointState state() const {
    return {static_cast<double>(stamp_ns) * 1e-9,
            Eigen::Map<const Eigen::VectorXd>(positions.data(), static_cast<Eigen::Index>(positions.size())),
            payload};
  }
};

}  // namespace cellmap::transport
