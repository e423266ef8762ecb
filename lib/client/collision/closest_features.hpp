// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: exact closest points of two separated boxes without iterating GJK, certified by a separating
// axis: a pair of points, one per box, is a closest pair when it reaches the axis's lower bound of the
// distance.

#include <Eigen/Core>

#include "relative_pose.hpp"
#include "separating_axes.hpp"

namespace cellmap::collision {

/// Support-feature certificate for a separating `axis` (gap > 0): if the features of A and B extreme along
/// it hold a pair of points exactly `gap` apart (a vertex projecting into the facing face, or two edges whose
/// common perpendicular meets both), writes that pair (A's frame) and returns true.
[[nodiscard]] bool certify_by_axis(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb,
                                   const RelativePose& rel, const SeparatingAxis& axis, Eigen::Vector3d* pa,
                                   Eigen::Vector3d* pb);

}  // namespace cellmap::collision
