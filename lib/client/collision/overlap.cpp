// SPDX-License-Identifier: Apache-2.0
#include <algorithm>
#include <cmath>

#include "cellmap/collision/box_distance.hpp"

namespace cellmap::collision {

bool overlap(const Obb& a, const Obb& b, double margin) {
  const Eigen::Vector3d d = b.center - a.center;
  // Bounding spheres first: most pairs of a scene are far apart, and this costs a fraction of the 15 axes.
  const double reach = a.half_extents.norm() + b.half_extents.norm() + margin;
  if (d.squaredNorm() > reach * reach) return false;
  const Eigen::Matrix3d R = a.rotation.transpose() * b.rotation;
  const Eigen::Vector3d t = a.rotation.transpose() * d;
  // The epsilon keeps near-parallel edge axes (cross products ~ 0) from separating by rounding alone
  // (Gottschalk, Lin, Manocha 1996); it makes the test conservative by ~1e-6 of the box size on edge axes.
  const Eigen::Matrix3d absR = R.cwiseAbs().array() + 1e-6;
  const Eigen::Vector3d& ha = a.half_extents;
  const Eigen::Vector3d& hb = b.half_extents;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(t[i]) > ha[i] + hb.dot(absR.row(i)) + margin) return false;
  }
  for (int j = 0; j < 3; ++j) {
    if (std::abs(t.dot(R.col(j))) > ha.dot(absR.col(j)) + hb[j] + margin) return false;
  }
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3;
    const int i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3;
      const int j2 = (j + 2) % 3;
      const double ra = ha[i1] * absR(i2, j) + ha[i2] * absR(i1, j);
      const double rb = hb[j1] * absR(i, j2) + hb[j2] * absR(i, j1);
      const double tl = t[i2] * R(i1, j) - t[i1] * R(i2, j);
      // |L| = sin(angle between the edges); only needed when there is a margin.
      const double grow = margin > 0.0 ? margin * std::sqrt(std::max(0.0, 1.0 - R(i, j) * R(i, j))) : 0.0;
      if (std::abs(tl) > ra + rb + grow) return false;
    }
  }
  return true;
}

}  // namespace cellmap::collision
