#pragma once
// A sweep: the frames taken at the stops of one pass over the working area, in the cell frame.

#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <vector>

#include "cellmap/frame/cloud.hpp"
#include "cellmap/frame/frame.hpp"

namespace cellmap {

/// The valid points of one frame in the cell frame, with the sensor origin they were seen from (occupancy
/// ray-casts free space from `origin_C` to each point), and where the sensor was and what it could see (for
/// the viewer).
struct Scan final {
  Eigen::Vector3d origin_C = Eigen::Vector3d::Zero();
  Cloud points_C;
  std::string sensor;
  /// The frame's sensor pose; origin_C is its position.
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  std::optional<FieldOfView> field_of_view;  ///< in the sensor frame S; none if unknown
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
/// position; the frame's sensor, pose and field of view (see field_of_view(Frame)). Non-finite points (an
/// organized cloud's NaN pixels) are skipped. Every source — real or simulated — goes through this one
/// function.
[[nodiscard]] Scan to_scan(const Frame& frame);

/// The sweep of `frames`, in the order given: one Scan per frame (to_scan), stamp = the last frame's stamp
/// (0 when there are no frames).
[[nodiscard]] Sweep merge_frames(const std::vector<Frame>& frames);

}  // namespace cellmap
