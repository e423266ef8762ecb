// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: GJK's sub-algorithm, the point of a simplex closest to the origin, by "signed volumes"
// (Montanari, Petrinic, Barbieri, ACM TOG 2017): the supporting face is decided by signs of (projected)
// volumes, which stays robust for nearly degenerate simplices, and faces are recursed into only when needed.

#include <array>
#include <limits>

#include "minkowski_support.hpp"

namespace cellmap::collision {

/// The sub-simplex supporting the closest point: its vertex indices (increasing), barycentric weights and
/// squared distance to the origin. n = 4 means the origin lies inside the tetrahedron.
struct SubSimplex final {
  std::array<int, 4> index{};
  std::array<double, 4> lambda{};
  int n = 0;
  double distance2 = std::numeric_limits<double>::infinity();
};

/// Closest point to the origin of the simplex s[0, n), 1 <= n <= 4.
[[nodiscard]] SubSimplex closest_to_origin(const std::array<SupportVertex, 4>& s, int n);

}  // namespace cellmap::collision
