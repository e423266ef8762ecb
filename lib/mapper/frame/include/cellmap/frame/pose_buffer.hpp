// SPDX-License-Identifier: Apache-2.0
#pragma once
// Robot pose input of the map maker: stamped end-effector poses, interpolated to frame times, and the
// composition X_CS = X_CE * X_ES that gives every frame its sensor pose.

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>

#include "cellmap/frame/frame.hpp"
#include "cellmap/robot/robot.hpp"

namespace cellmap {

/// The end-effector (tool) pose in the cell frame at one instant.
struct StampedPose final {
  double stamp = 0.0;                                      ///< seconds, same clock as the frames
  Eigen::Isometry3d X_CE = Eigen::Isometry3d::Identity();  ///< tool pose in the cell frame
};

/// Outcome of a pose lookup.
enum class PoseLookup {
  kFound,    ///< interpolated between two samples that bracket the time, both within the tolerance
  kPending,  ///< the time is newer than every sample: the pose may still arrive, ask again later
  kMissing,  ///< no pose within tolerance will ever cover this time: drop the frame
};

/// A time-ordered buffer of tool poses fed by the robot (a DDS reader, a replay file, a test) and read by the
/// sensor loop. Lookups interpolate position linearly and rotation by slerp between the two samples that
/// bracket the time; a lookup never extrapolates and never bridges a gap: both samples must lie within
/// `tolerance` of the requested time (an exact sample time needs only that sample).
/// Feeding joint vectors: compute X_CE = robot.tool_pose(q) and push it; between two samples of a fast
/// controller (≥ 100 Hz) the pose-space interpolation differs from FK(interpolated q) by far less than a
/// voxel. Thread-safe: push() and at() may run on different threads.
class PoseBuffer final {
 public:
  /// @param tolerance  seconds: the largest distance in time from a frame to each of its bracketing samples
  /// @param capacity   samples kept; the oldest are dropped first
  /// @throws Error if tolerance is not positive or capacity < 2.
  explicit PoseBuffer(double tolerance, std::size_t capacity = 4096);

  /// Adds a sample; samples may arrive out of order (they are inserted in time order); a sample with the same
  /// stamp as a kept one replaces it.
  /// @throws Error if the stamp or the pose is not finite, or the rotation is not orthonormal (|RᵀR - I| >
  /// 1e-6).
  void push(double stamp, const Eigen::Isometry3d& X_CE);
  void push(const StampedPose& sample) { push(sample.stamp, sample.X_CE); }
  /// Adds the tool pose of joint vector `q` at `stamp`: X_CE = robot.tool_pose(q).
  /// @throws Error as push(), or as Robot::tool_pose for a q of the wrong size or with non-finite entries.
  void push_joints(double stamp, const Robot& robot, const Eigen::VectorXd& q) {
    push(stamp, robot.tool_pose(q));
  }

  struct Result {
    PoseLookup status = PoseLookup::kMissing;
    Eigen::Isometry3d X_CE = Eigen::Isometry3d::Identity();  ///< valid only when status is kFound
  };
  /// The tool pose at `stamp`. Costs O(log n).
  [[nodiscard]] Result at(double stamp) const;

  [[nodiscard]] double tolerance() const { return tolerance_; }
  [[nodiscard]] std::size_t size() const;

 private:
  double tolerance_;
  std::size_t capacity_;
  mutable std::mutex mutex_;
  std::deque<StampedPose> samples_;  // sorted by stamp
};

/// Linear position and slerp rotation between two poses; t in [0, 1]. Pure function.
[[nodiscard]] Eigen::Isometry3d interpolate_pose(const Eigen::Isometry3d& X_a, const Eigen::Isometry3d& X_b,
                                                 double t);

/// Gives frames their sensor pose X_CS = X_CE(stamp) * X_ES, counting the frames it had to drop.
/// Not thread-safe (one per sensor loop); the PoseBuffer it reads is.
class SensorPoser final {
 public:
  /// @param X_ES  hand-eye extrinsic: the sensor pose in the end-effector frame.
  /// @throws Error if X_ES is not finite or its rotation not orthonormal.
  explicit SensorPoser(const Eigen::Isometry3d& X_ES);

  /// Sets frame.X_CS from the buffer. Returns kFound (posed), kPending (leave the frame unchanged and retry
  /// once newer poses arrived, or call give_up()), or kMissing (frame counted as dropped; never fuse it).
  PoseLookup attach(Frame& frame, const PoseBuffer& poses);
  /// Counts a pending frame as dropped (its pose did not arrive in time).
  void give_up() { ++dropped_; }

  [[nodiscard]] std::uint64_t posed() const { return posed_; }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }
  [[nodiscard]] const Eigen::Isometry3d& X_ES() const { return X_ES_; }

 private:
  Eigen::Isometry3d X_ES_;
  std::uint64_t posed_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace cellmap
