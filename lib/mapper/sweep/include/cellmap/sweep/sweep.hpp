// SPDX-License-Identifier: Apache-2.0
#pragma once
// A sweep: the frames taken at the stops of one pass over the working area, in the cell frame.

#include <Eigen/Core>

#include <vector>

#include "cellmap/frame/cloud.hpp"
#include "cellmap/frame/frame.hpp"

namespace cellmap {

/// The valid points of one frame in the cell frame, with the sensor origin they were seen from (occupancy
/// ray-casts free space from `origin_C` to each point).
struct Scan final {
  Eigen::Vector3d origin_C = Eigen::Vector3d::Zero();
  Cloud points_C;
  /// Ends of clear-only rays (cell frame): each clears free space from `origin_C` up to the end and marks
  /// nothing occupied (the end's voxel is neither hit nor cleared) — a line of sight known to be free only up
  /// to there, e.g. up to the robot's near surface (self_filter). Usually empty.
  Cloud clear_C;
};

/// One sweep: every frame of one pass, in the order taken. `stamp` is the time of the last frame, seconds.
struct Sweep final {
  double stamp = 0.0;
  std::vector<Scan> scans;

  /// All points of all scans in one cloud (the "merged sweep cloud").
  [[nodiscard]] Cloud merged() const;
  [[nodiscard]] std::size_t point_count() const;
};

/// The frame's valid points moved into the cell frame (p_C = X_CS · p_S), seen from origin_C = the sensor
/// position. Non-finite points (an organized cloud's NaN pixels) are skipped. Every source — real or
/// simulated — goes through this one function.
[[nodiscard]] Scan to_scan(const Frame& frame);

/// to_scan(frame) without copying the points: the frame's points are transformed where they lie and move
/// into the scan, leaving `frame.points_S` empty (the frame keeps its pose, stamp and depth image). What
/// the cell pipeline does with a sweep's frames, so that a frame's points are not held twice.
[[nodiscard]] Scan move_to_scan(Frame& frame);

/// The sweep of `frames`, in the order given: one Scan per frame (to_scan), stamp = the last frame's stamp
/// (0 when there are no frames).
[[nodiscard]] Sweep merge_frames(const std::vector<Frame>& frames);

}  // namespace cellmap
