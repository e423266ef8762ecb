// SPDX-License-Identifier: Apache-2.0
#pragma once
// How a camera's stream of frames becomes sweeps: each frame gets its sensor pose from the robot's poses
// (X_CS = X_CE(stamp) * X_ES), frames without a pose are dropped, and posed frames are grouped by their
// stamps into sweeps.

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

#include "cellmap/frame/frame.hpp"
#include "cellmap/frame/pose_buffer.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap {

/// How frames are grouped into sweeps. Seconds.
struct SweepParams final {
  /// A sweep spans at most this much frame time: a frame stamped at or after the sweep's first stamp + period
  /// closes the sweep and starts the next one (0: every frame is its own sweep, handed out when the next
  /// frame arrives or the source stops streaming).
  double period = 0.5;
  /// A sweep also closes once it holds this many frames (0: no limit).
  std::size_t max_frames = 0;
  /// A frame newer than every robot pose waits this long (on the caller's clock) for its pose; then it is
  /// dropped. Covers the robot controller's publishing delay.
  double pose_wait = 0.5;

  /// @throws Error if a time is negative or not finite.
  void validate() const;
};

/// Poses frames in arrival order and groups them into sweeps. Frames without a pose within the pose buffer's
/// tolerance are counted in dropped() and never reach a sweep. A sweep's stamp is its last frame's stamp.
/// Times passed as `now` are seconds on any monotonic clock (the pose wait is measured on it), so the logic
/// is tested without sleeping. Not thread-safe (one per sensor loop); the PoseBuffer it reads is.
class SweepAssembler final {
 public:
  /// @param X_ES  hand-eye extrinsic: the sensor pose in the end-effector frame.
  /// @throws Error if the grouping is invalid or X_ES is not a rigid transform.
  SweepAssembler(const SweepParams& grouping, const Eigen::Isometry3d& X_ES);

  /// Queues a frame (points in the sensor frame S) that arrived at `now`. Its depth image is released.
  void add(Frame frame, double now);
  /// Poses the queued frames whose poses are known (oldest first), drops those whose pose will never come or
  /// waited longer than pose_wait, and returns the sweeps this completed, oldest first.
  [[nodiscard]] std::vector<Sweep> poll(const PoseBuffer& poses, double now);
  /// End of the stream (recording ended, device lost): poses what can be posed now, drops the frames still
  /// waiting for a pose, and returns the sweeps this completed including the open one, oldest first.
  [[nodiscard]] std::vector<Sweep> flush(const PoseBuffer& poses);

  [[nodiscard]] std::uint64_t posed() const { return poser_.posed(); }
  /// Frames dropped because no pose covered them (never fused).
  [[nodiscard]] std::uint64_t dropped() const { return poser_.dropped(); }
  /// Frames queued, waiting for their pose.
  [[nodiscard]] std::size_t waiting() const { return waiting_.size(); }

 private:
  struct Waiting {
    Frame frame;
    double arrived = 0.0;
  };
  // Adds a posed frame to the open sweep; a sweep it closes goes to `done`.
  void group(const Frame& frame, std::vector<Sweep>& done);
  // Poses waiting frames; a frame still pending that arrived before `give_up_before` is dropped.
  void pose_waiting(const PoseBuffer& poses, double give_up_before, std::vector<Sweep>& done);

  SweepParams grouping_;
  SensorPoser poser_;
  std::deque<Waiting> waiting_;
  Sweep open_;
  double open_first_stamp_ = 0.0;
};

}  // namespace cellmap
