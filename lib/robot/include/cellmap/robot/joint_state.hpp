// SPDX-License-Identifier: Apache-2.0
#pragma once
// The robot's state at one instant as the controller reports it: joint positions and what the tool holds.
// The one joint-sample type of the DDS topic cellmap/robot_joints (transport), the joint buffer (frame) and
// the simulator.

#include <Eigen/Geometry>

#include <optional>

namespace cellmap {

/// What the tool holds: a box in the tool frame E (pose X_EB of its centre and axes, half extents in metres,
/// >= 0). While held it is part of the robot: it moves with the tool and is filtered out with the robot.
struct Payload final {
  Eigen::Isometry3d X_EB = Eigen::Isometry3d::Identity();
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
};

/// The joint positions q (metres or radians, in the robot's joint order) at `stamp` (seconds, the frames'
/// clock) and the payload held then (none: the tool is empty).
struct JointState final {
  double stamp = 0.0;
  Eigen::VectorXd q;
  std::optional<Payload> payload;
};

}  // namespace cellmap
