// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: the 15 separating axes of two boxes (3 + 3 face normals, 9 edge-edge cross products) with exact
// rotation terms, for the exact depth and the distance lower bound.

#include <Eigen/Core>

#include <cmath>
#include <limits>

#include "cellmap/collision/box_distance.hpp"
#include "relative_pose.hpp"

namespace cellmap::collision {

/// The largest separation along the axes (negative: minus the smallest overlap) with its unit axis in A's
/// frame, pointing from A to B, and which axis it is.
struct SeparatingAxis final {
  double gap = -std::numeric_limits<double>::infinity();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  enum Kind { kFaceA, kFaceB, kEdges } kind = kFaceA;
  int i = 0;  ///< face of A, or A's edge direction
  int j = 0;  ///< face of B, or B's edge direction
};

namespace separating_axes_detail {

// Gaps along the 6 face normals: [0, 3) A's faces, [3, 6) B's faces; `tb` = t in B's axes.
struct FaceGaps {
  double gap[6];
  double tb[3];
  int best = 0;
};

inline FaceGaps face_gaps(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb, const RelativePose& rel,
                          const Eigen::Matrix3d& absR) {
  FaceGaps f;
  for (int i = 0; i < 3; ++i) f.gap[i] = std::abs(rel.t[i]) - ha[i] - hb.dot(absR.row(i));
  for (int j = 0; j < 3; ++j) {
    f.tb[j] = rel.t.dot(rel.R.col(j));
    f.gap[3 + j] = std::abs(f.tb[j]) - ha.dot(absR.col(j)) - hb[j];
  }
  for (int m = 1; m < 6; ++m) f.best = f.gap[m] > f.gap[f.best] ? m : f.best;
  return f;
}

inline SeparatingAxis face_axis(const FaceGaps& f, const RelativePose& rel) {
  SeparatingAxis out;
  out.gap = f.gap[f.best];
  if (f.best < 3) {
    out.kind = SeparatingAxis::kFaceA;
    out.i = f.best;
    out.axis = Eigen::Vector3d::Unit(f.best) * sign_of(rel.t[f.best]);
  } else {
    out.kind = SeparatingAxis::kFaceB;
    out.j = f.best - 3;
    out.axis = rel.R.col(out.j) * sign_of(f.tb[out.j]);
  }
  return out;
}

// The best edge axis L = e_i x R.col(j) if it beats `best_gap`; kind stays kFaceA when none does.
// |L|^2 = R(i1, j)^2 + R(i2, j)^2. Near-parallel edges (|L| < 1e-8) are skipped: their facets of the
// Minkowski difference degenerate and the neighbouring axes bound the same overlap.
inline SeparatingAxis best_edge_axis(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb,
                                     const RelativePose& rel, const Eigen::Matrix3d& absR, double best_gap) {
  const Eigen::Matrix3d& R = rel.R;
  const Eigen::Vector3d& t = rel.t;
  SeparatingAxis out;
  out.gap = best_gap;
  double best_tl = 0.0;
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3;
    const int i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3;
      const int j2 = (j + 2) % 3;
      const double length2 = R(i1, j) * R(i1, j) + R(i2, j) * R(i2, j);
      if (length2 < 1e-16) continue;
      const double ra = ha[i1] * absR(i2, j) + ha[i2] * absR(i1, j);
      const double rb = hb[j1] * absR(i, j2) + hb[j2] * absR(i, j1);
      const double tl = t[i2] * R(i1, j) - t[i1] * R(i2, j);
      const double numerator = std::abs(tl) - ra - rb;
      // With a positive gap known, an edge axis can only win with a positive numerator and then the
      // comparison needs no square root; most edge axes are discarded here.
      if (out.gap > 0.0 && (numerator <= 0.0 || numerator * numerator <= out.gap * out.gap * length2))
        continue;
      const double gap = numerator / std::sqrt(length2);
      if (!(gap > out.gap)) continue;
      out.gap = gap;
      out.kind = SeparatingAxis::kEdges;
      out.i = i;
      out.j = j;
      best_tl = tl;
    }
  }
  if (out.kind == SeparatingAxis::kEdges) {
    const Eigen::Vector3d L = Eigen::Vector3d::Unit(out.i).cross(R.col(out.j));
    out.axis = L * (sign_of(best_tl) / L.norm());
  }
  return out;
}

}  // namespace separating_axes_detail

/// The best of the 15 axes, or with `faces_only` of the 6 face axes (a valid lower bound of the distance
/// when positive, and cheap). Inlined into its callers so that R and t stay in registers.
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline SeparatingAxis
best_separating_axis(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb, const RelativePose& rel,
                     bool faces_only = false) {
  using namespace separating_axes_detail;
  const Eigen::Matrix3d absR = rel.R.cwiseAbs();
  const FaceGaps faces = face_gaps(ha, hb, rel, absR);
  if (faces_only) return face_axis(faces, rel);
  const SeparatingAxis edges = best_edge_axis(ha, hb, rel, absR, faces.gap[faces.best]);
  return edges.kind == SeparatingAxis::kEdges ? edges : face_axis(faces, rel);
}

/// Exact penetration along the 15 separating axes: the largest separation (distance > 0, a lower bound of
/// the true distance) or, when no axis separates, minus the penetration depth (exact: the facets of the
/// Minkowski difference of two boxes have exactly these normals). normal points from A to B (cell frame).
/// Points are not filled.
[[nodiscard]] SignedDistance separating_axis_depth(const Obb& a, const Obb& b);

}  // namespace cellmap::collision
