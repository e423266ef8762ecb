#pragma once
// Internal: exact closest points of two separated boxes without iterating GJK, certified by the
// separating axis: a pair of points, one per box, is a closest pair when it reaches the axis's lower bound
// of the distance, or when the two points are mutually closest.

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

/// Mutually closest points by alternating projections: from B's point closest to A's centre, project onto A,
/// back onto B, and so on; when a point maps back onto itself (to 1e-13 of the scene size) the two points
/// are mutually closest, and mutually closest points of two convex sets are a closest pair (the direction
/// between them lies in both normal cones). Where the projections land on an edge of each box, the step goes
/// straight to the closest points of the two edge lines, so crossing edges need no zig-zag. Writes the pair
/// (A's frame) and returns true when it converged within a few steps (> 95 % of random separated pairs);
/// overlapping boxes converge to a common point.
[[nodiscard]] bool mutually_closest_points(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb,
                                           const RelativePose& rel, Eigen::Vector3d* pa, Eigen::Vector3d* pb);

}  // namespace cellmap::collision
