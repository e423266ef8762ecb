#pragma once
// A sweep: the frames taken at the stops of one pass over the working area, in the cell frame.

#include <Eigen/Core>

#include <vector>

#include "cellmap/common/cloud.hpp"

namespace cellmap {

/// The valid points of one frame in the cell frame, with the sensor origin they were seen from (occupancy
/// ray-casts free space from `origin_C` to each point).
struct Scan final {
  Eigen::Vector3d origin_C = Eigen::Vector3d::Zero();
  Cloud points_C;
};

/// One sweep: every frame of one pass, in the order taken. `stamp` is the time of the last frame, seconds.
struct Sweep final {
  double stamp = 0.0;
  std::vector<Scan> scans;

  /// All points of all scans in one cloud (the "merged sweep cloud").
  [[nodiscard]] Cloud merged() const;
  [[nodiscard]] std::size_t point_count() const;
};

}  // namespace cellmap
