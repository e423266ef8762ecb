// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a sensor can see, in its own frame S: the one description of a field of view, shared by the sensors
// that know theirs and the viewer that draws it.

#include <Eigen/Core>

#include <vector>

namespace cellmap {

/// The edge of a sensor's field of view: unit rays in the sensor frame S along its border, out to
/// `max_range` metres. A camera's frustum is its four corner rays in image order (top left, top right,
/// bottom right, bottom left; `closed`: the last joins the first); a line scanner's fan is beams from its
/// first to its last (open).
struct FieldOfView final {
  std::vector<Eigen::Vector3d> outline_S;
  bool closed = false;
  double max_range = 0.0;
};

}  // namespace cellmap
