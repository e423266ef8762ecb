// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: the support mapping of the Minkowski difference D = A - B of two boxes, in A's frame, shared by
// GJK and EPA.

#include <Eigen/Core>

#include "relative_pose.hpp"

namespace cellmap::collision {

/// A vertex w of D with the box vertices it comes from; `id` packs the sign patterns of both (bits 0-2: A's
/// vertex, bits 3-5: B's), so a repeated support vertex is recognised exactly.
struct SupportVertex final {
  Eigen::Vector3d w;
  int id = -1;
};

/// A's vertex of a support vertex, from its sign bits; B's vertex is then a - w.
[[nodiscard]] inline Eigen::Vector3d vertex_of_a(int id, const Eigen::Vector3d& ha) {
  return Eigen::Vector3d((id & 1) ? ha[0] : -ha[0], (id & 2) ? ha[1] : -ha[1], (id & 4) ? ha[2] : -ha[2]);
}

/// The vertex of D furthest along d (ties to the + side of each box axis).
struct MinkowskiSupport final {
  const Eigen::Vector3d& ha;
  const Eigen::Vector3d& hb;
  const RelativePose& rel;

  [[nodiscard]] SupportVertex operator()(const Eigen::Vector3d& d) const {
    SupportVertex v;
    int id = 0;
    Eigen::Vector3d a;
    for (int k = 0; k < 3; ++k) {
      const bool positive = d[k] >= 0.0;
      a[k] = positive ? ha[k] : -ha[k];
      id |= positive ? (1 << k) : 0;
    }
    const Eigen::Vector3d d_b = -(rel.R.transpose() * d);
    Eigen::Vector3d s_b;
    for (int k = 0; k < 3; ++k) {
      const bool positive = d_b[k] >= 0.0;
      s_b[k] = positive ? hb[k] : -hb[k];
      id |= positive ? (8 << k) : 0;
    }
    v.w = a - (rel.R * s_b + rel.t);
    v.id = id;
    return v;
  }
};

}  // namespace cellmap::collision
