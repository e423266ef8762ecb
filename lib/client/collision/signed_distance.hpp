// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: the two halves of signed_distance, shared with EPA, and its baseline build.

#include <Eigen/Core>

#include "cellmap/collision/box_distance.hpp"
#include "gjk.hpp"
#include "separating_axes.hpp"

namespace cellmap::collision {

/// Distance of separated boxes (axis.gap > 0) in A's frame: the support-feature certificate when it applies,
/// else GJK started along the axis.
[[nodiscard]] GjkResult separated_distance(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb,
                                           const RelativePose& rel, const SeparatingAxis& axis);

/// Distance of boxes in A's frame when mutually closest points are found at a distance well above rounding
/// (false otherwise: touching, overlapping or slowly converging).
[[nodiscard]] bool clearly_separated(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb,
                                     const RelativePose& rel, GjkResult* result);

/// Touching or overlapping boxes with penetration `depth` >= 0 along `axis_a` (unit, A's frame, A → B): the
/// result in the cell frame with witness points. B moved out along the axis by depth + clearance touches
/// nothing, and the closest points there (exactly `clearance` apart, along the axis) map back to A and the
/// original B.
[[nodiscard]] SignedDistance penetration_witnesses(const Obb& a, const Obb& b, const RelativePose& rel,
                                                   double depth, const Eigen::Vector3d& axis_a);

/// signed_distance as compiled for the x86-64 baseline (SSE2), which signed_distance runs where the CPU has
/// no AVX: the same numbers, bit for bit (for the test that says so).
[[nodiscard]] SignedDistance signed_distance_baseline(const Obb& a, const Obb& b);

}  // namespace cellmap::collision
