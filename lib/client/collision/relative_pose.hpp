// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: box B seen from box A, the frame every box-box algorithm here computes in.

#include <Eigen/Core>

#include "cellmap/collision/obb.hpp"

namespace cellmap::collision {

/// B expressed in A's frame: R = R_AB (columns are B's axes in A), t = p_AB (B's centre in A).
struct RelativePose final {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
};

[[nodiscard]] inline RelativePose relative_pose(const Obb& a, const Obb& b) {
  return {a.rotation.transpose() * b.rotation, a.rotation.transpose() * (b.center - a.center)};
}

/// +1 for x >= 0, else -1: picks a box vertex extreme along a direction (ties go to the + side).
[[nodiscard]] inline double sign_of(double x) {
  return x >= 0.0 ? 1.0 : -1.0;
}

}  // namespace cellmap::collision
