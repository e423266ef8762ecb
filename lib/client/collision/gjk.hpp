// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: GJK minimum distance between two boxes (with the signed-volumes sub-algorithm), the fallback of
// signed_distance for the pairs no closest-feature certificate settles, and EPA's start.

#include <Eigen/Core>

#include <array>

#include "cellmap/collision/obb.hpp"
#include "minkowski_support.hpp"

namespace cellmap::collision {

/// Result of GJK: `distance` >= 0 and witness points; `intersecting` when the boxes touch or overlap (then
/// distance is 0 and the points are a common point of both boxes, if touching, or unspecified if
/// overlapping).
struct GjkResult final {
  double distance = 0.0;
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  bool intersecting = false;
  int iterations = 0;
};

/// GJK's final simplex and the barycentric weights of its closest point to the origin.
struct Simplex final {
  std::array<SupportVertex, 4> v;
  std::array<double, 4> lambda{};
  int n = 0;
};

/// GJK in A's frame (points in A's frame). Starts from D's centre -t, or along `towards_b` (a direction from
/// A to B, e.g. a separating axis) when given. Stops when the new support vertex is already in the simplex
/// (exact and finite on polytopes), or when the gain falls below a relative (1e-14 of |v|^2) or absolute
/// (1e-24 m^2 scaled by the scene size) threshold. `simplex_out` receives the final simplex.
[[nodiscard]] GjkResult gjk(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb, const RelativePose& rel,
                            Simplex* simplex_out = nullptr, const Eigen::Vector3d* towards_b = nullptr);

/// GJK between two boxes in the cell frame.
[[nodiscard]] GjkResult gjk_distance(const Obb& a, const Obb& b);

}  // namespace cellmap::collision
