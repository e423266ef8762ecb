// SPDX-License-Identifier: Apache-2.0
#pragma once
// Bounding spheres: the paper's cheap, conservative approximation of a box by N spheres, and the sphere
// queries.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <Eigen/Core>

#include <vector>

#include "cellmap/collision/obb.hpp"

namespace cellmap::collision {

/// A sphere in frame F, metres.
struct Sphere final {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// Covers `box` with exactly `n` spheres. Covering rule (general N): cut the box into nx × ny × nz equal
/// cells with nx·ny·nz = n, choosing among all ordered factorizations of n the one whose cells have the
/// smallest half diagonal; each cell gets its circumscribed sphere (centre = cell centre, radius = cell half
/// diagonal). Every point of the box lies in some cell and every cell lies in its sphere, so the spheres
/// cover the box: the sphere method never misses a collision (it over-approximates by at most the radius
/// minus the cell's half extent). N = 1 is the circumscribed sphere, N = 2 splits the longest axis, N = 6 on
/// a cube is 3 × 2 × 1. Thread-safe. @throws Error if n < 1.
[[nodiscard]] std::vector<Sphere> sphere_cover(const Obb& box, int n);

/// Distance between sphere surfaces, ||c2 − c1|| − r1 − r2 (negative when they overlap).
[[nodiscard]] inline double sphere_distance(const Sphere& a, const Sphere& b) {
  return (b.center - a.center).norm() - a.radius - b.radius;
}

/// The paper's non-collision condition with safety margin δ: ||r2 − r1|| ≥ r1 + r2 + δ (squared, no root).
[[nodiscard]] inline bool spheres_clear(const Sphere& a, const Sphere& b, double margin) {
  const double reach = a.radius + b.radius + margin;
  return reach <= 0.0 || (b.center - a.center).squaredNorm() >= reach * reach;
}

/// Signed distance from a sphere to a box (negative: penetration depth of the sphere into the box).
[[nodiscard]] double sphere_box_distance(const Sphere& sphere, const Obb& box);

/// Smallest sphere_distance over all pairs (a_i, b_j): the sphere method's distance between two covered
/// shapes, a lower bound of their true distance. +infinity if either set is empty.
[[nodiscard]] double sphere_set_distance(const std::vector<Sphere>& a, const std::vector<Sphere>& b);

}  // namespace cellmap::collision
