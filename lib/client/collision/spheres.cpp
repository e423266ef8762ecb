// SPDX-License-Identifier: Apache-2.0
#include "cellmap/collision/spheres.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap::collision {

std::vector<Sphere> sphere_cover(const Obb& box, int n) {
  if (n < 1) throw Error("sphere_cover: sphere count must be >= 1, got " + std::to_string(n));
  const Eigen::Vector3d& h = box.half_extents;
  Eigen::Vector3i best(n, 1, 1);
  double best_radius2 = std::numeric_limits<double>::infinity();
  for (int nx = 1; nx <= n; ++nx) {
    if (n % nx != 0) continue;
    for (int ny = 1; ny <= n / nx; ++ny) {
      if ((n / nx) % ny != 0) continue;
      const Eigen::Vector3i cells(nx, ny, n / nx / ny);
      const double radius2 = h.cwiseQuotient(cells.cast<double>()).squaredNorm();
      if (radius2 < best_radius2) {
        best_radius2 = radius2;
        best = cells;
      }
    }
  }
  const Eigen::Vector3d cell_half = h.cwiseQuotient(best.cast<double>());
  const double radius = cell_half.norm();
  std::vector<Sphere> spheres;
  spheres.reserve(n);
  for (int i = 0; i < best.x(); ++i) {
    for (int j = 0; j < best.y(); ++j) {
      for (int k = 0; k < best.z(); ++k) {
        const Eigen::Vector3d p_B =
            -h + cell_half.cwiseProduct(Eigen::Vector3d(2 * i + 1, 2 * j + 1, 2 * k + 1));
        spheres.push_back({box.center + box.rotation * p_B, radius});
      }
    }
  }
  return spheres;
}

double sphere_box_distance(const Sphere& sphere, const Obb& box) {
  const Eigen::Vector3d p_B = box.rotation.transpose() * (sphere.center - box.center);
  const Eigen::Vector3d outside = p_B.cwiseAbs() - box.half_extents;
  const double to_surface =
      outside.maxCoeff() > 0.0 ? outside.cwiseMax(0.0).norm() : outside.maxCoeff();  // inside: minus depth
  return to_surface - sphere.radius;
}

double sphere_set_distance(const std::vector<Sphere>& a, const std::vector<Sphere>& b) {
  double best = std::numeric_limits<double>::infinity();
  for (const Sphere& sa : a) {
    for (const Sphere& sb : b) best = std::min(best, sphere_distance(sa, sb));
  }
  return best;
}

}  // namespace cellmap::collision
