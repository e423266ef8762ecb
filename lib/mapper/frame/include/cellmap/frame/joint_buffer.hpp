// SPDX-License-Identifier: Apache-2.0
#pragma once
// Joint-state input of the map maker: stamped joint samples of the robot (cellmap/robot_joints, a
// simulator), interpolated to frame times and turned into link poses by the robot model. The joint-space
// sibling of PoseBuffer (pose_buffer.hpp), with the same lookup rules.

#include <Eigen/Geometry>

#include <cstddef>
#include <deque>
#include <mutex>
#include <vector>

#include "cellmap/frame/pose_buffer.hpp"
#include "cellmap/robot/joint_state.hpp"
#include "cellmap/robot/robot.hpp"

namespace cellmap {

/// A time-ordered buffer of joint samples of one robot, fed by the controller's topic and read by the sensor
/// loop. A lookup interpolates every joint linearly between the two samples that bracket the time and runs
/// forward kinematics; it never extrapolates and never bridges a gap: both samples must lie within
/// `tolerance` of the requested time (an exact sample time needs only that sample). The payload is the one of
/// the nearer sample (the earlier one at equal distance). Thread-safe: push() and at() may run on different
/// threads.
class JointBuffer final {
 public:
  /// @param tolerance  seconds: the largest distance in time from a frame to each of its bracketing samples
  /// @param capacity   samples kept; the oldest are dropped first
  /// @throws Error if tolerance is not positive or capacity < 2.
  JointBuffer(Robot robot, double tolerance, std::size_t capacity = 4096);

  /// Adds a sample; samples may arrive out of order (they are inserted in time order); a sample with the same
  /// stamp as a kept one replaces it.
  /// @throws Error if the stamp is not finite, q does not have robot().dof() finite entries, or the payload
  /// is not finite, has a negative half extent or a rotation that is not orthonormal.
  void push(const JointState& sample);

  /// The robot at one instant.
  struct Result {
    PoseLookup status = PoseLookup::kMissing;
    JointState state;                     ///< interpolated joints, stamp = the requested time (kFound only)
    std::vector<Eigen::Isometry3d> X_CL;  ///< every link's pose, in robot().link_names() order (kFound only)
    [[nodiscard]] const Eigen::Isometry3d& X_CE() const { return X_CL.back(); }  ///< the tool pose
  };
  /// The robot at `stamp`. Costs O(log n) plus one forward kinematics.
  [[nodiscard]] Result at(double stamp) const;

  [[nodiscard]] const Robot& robot() const { return robot_; }
  [[nodiscard]] double tolerance() const { return tolerance_; }
  [[nodiscard]] std::size_t size() const;

 private:
  Robot robot_;
  double tolerance_;
  std::size_t capacity_;
  mutable std::mutex mutex_;
  std::deque<JointState> samples_;  // sorted by stamp
};

}  // namespace cellmap
