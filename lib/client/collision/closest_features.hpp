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

/// Projection certificate: starts at a vertex extreme along `axis` and alternates closest-point projections
/// between the boxes (a few steps, from B's side then from A's); when a point maps back onto itself the two
/// points are mutually closest, and mutually closest points of two convex sets are a closest pair (the
/// direction between them lies in both normal cones). Covers vertex-vertex, vertex-edge and many edge-face
/// contacts. Writes the pair (A's frame) and returns true when it converged.
[[nodiscard]] bool certify_by_projections(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb,
                                          const RelativePose& rel, const SeparatingAxis& axis,
                                          Eigen::Vector3d* pa, Eigen::Vector3d* pb);

/// Either certificate.
[[nodiscard]] inline bool certify_closest(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb,
                                          const RelativePose& rel, const SeparatingAxis& axis,
                                          Eigen::Vector3d* pa, Eigen::Vector3d* pb) {
  return certify_by_axis(ha, hb, rel, axis, pa, pb) || certify_by_projections(ha, hb, rel, axis, pa, pb);
}

}  // namespace cellmap::collision
