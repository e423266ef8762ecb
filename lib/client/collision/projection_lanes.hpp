#pragma once
// Internal: the first alternating projections of mutual_projections.hpp for L box pairs that share box A, as
// straight-line code over lanes of plain numbers (structure of arrays) that the compiler vectorises. They
// settle most separated pairs. signed_distance runs them with one lane and the dense batch with four, on the
// same code, so both give identical numbers.

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

#include "cellmap/collision/box_distance.hpp"
#include "cellmap/collision/obb.hpp"

namespace cellmap::collision {

/// L boxes B in structure of arrays: centre, rotation (column-major: rotation[r + 3 c] = R(r, c)), half
/// extents.
template <int L>
struct BoxLanes final {
  double center[3][L];
  double rotation[9][L];
  double half[3][L];

  /// Puts `box` into lane l.
  void set(int l, const Obb& box) {
    for (int i = 0; i < 3; ++i) center[i][l] = box.center[i];
    for (int i = 0; i < 9; ++i) rotation[i][l] = box.rotation.data()[i];
    for (int i = 0; i < 3; ++i) half[i][l] = box.half_extents[i];
  }
};

/// Each B seen from A (A's frame): R = R_AB (column-major), t = p_AB; then A's point p and B's point q after
/// two rounds of projections (p = clamp_A(q) exactly), gap = q - p, and whether they are certified mutually
/// closest at a distance well above rounding.
template <int L>
struct ProjectionLanes final {
  double R[9][L];
  double t[3][L];
  double p[3][L];
  double q[3][L];
  double gap[3][L];
  double gap2[L];
  int certified[L];
};

namespace projection_lanes_detail {

inline double clamp(double x, double h) {
  return std::min(std::max(x, -h), h);
}

}  // namespace projection_lanes_detail

/// B's pose in A's frame for every lane.
template <int L>
inline void relative_poses(const Obb& a, const BoxLanes<L>& b, ProjectionLanes<L>* out) {
  const double* Ra = a.rotation.data();  // Ra[k + 3 i] = R_CA(k, i)
  for (int l = 0; l < L; ++l) {
    const double d0 = b.center[0][l] - a.center[0];
    const double d1 = b.center[1][l] - a.center[1];
    const double d2 = b.center[2][l] - a.center[2];
    for (int i = 0; i < 3; ++i) out->t[i][l] = Ra[3 * i] * d0 + Ra[3 * i + 1] * d1 + Ra[3 * i + 2] * d2;
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 3; ++i) {
        out->R[i + 3 * j][l] = Ra[3 * i] * b.rotation[3 * j][l] + Ra[3 * i + 1] * b.rotation[3 * j + 1][l] +
                               Ra[3 * i + 2] * b.rotation[3 * j + 2][l];
      }
    }
  }
}

/// From A's point closest to B's centre: y0 = B's point closest to it, p = A's point closest to q = t + R y0,
/// y1 = B's point closest to p. Certified when p repeats the start or y1 repeats y0 (to 1e-13 of the scene
/// size): then p and q are mutually closest. Needs relative_poses first.
template <int L>
inline void project_twice(const Eigen::Vector3d& ha, const BoxLanes<L>& b, ProjectionLanes<L>* io) {
  using projection_lanes_detail::clamp;
  const double ha2 = ha.squaredNorm();
  for (int l = 0; l < L; ++l) {
    const double* hb[3] = {&b.half[0][l], &b.half[1][l], &b.half[2][l]};
    double R[9], t[3];
    for (int k = 0; k < 9; ++k) R[k] = io->R[k][l];
    for (int k = 0; k < 3; ++k) t[k] = io->t[k][l];
    double p0[3], y0[3], q[3], p[3], y1[3];
    for (int i = 0; i < 3; ++i) p0[i] = clamp(t[i], ha[i]);
    for (int j = 0; j < 3; ++j) {
      y0[j] = clamp(R[3 * j] * (p0[0] - t[0]) + R[3 * j + 1] * (p0[1] - t[1]) + R[3 * j + 2] * (p0[2] - t[2]),
                    *hb[j]);
    }
    for (int i = 0; i < 3; ++i) q[i] = t[i] + (R[i] * y0[0] + R[i + 3] * y0[1] + R[i + 6] * y0[2]);
    for (int i = 0; i < 3; ++i) p[i] = clamp(q[i], ha[i]);
    for (int j = 0; j < 3; ++j) {
      y1[j] = clamp(R[3 * j] * (p[0] - t[0]) + R[3 * j + 1] * (p[1] - t[1]) + R[3 * j + 2] * (p[2] - t[2]),
                    *hb[j]);
    }
    const double scale2 = ha2 + (*hb[0] * *hb[0] + *hb[1] * *hb[1] + *hb[2] * *hb[2]) +
                          (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    double moved_p = 0.0, moved_y = 0.0, gap2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      moved_p += (p[k] - p0[k]) * (p[k] - p0[k]);
      moved_y += (y1[k] - y0[k]) * (y1[k] - y0[k]);
      io->p[k][l] = p[k];
      io->q[k][l] = q[k];
      io->gap[k][l] = q[k] - p[k];
      gap2 += io->gap[k][l] * io->gap[k][l];
    }
    io->gap2[l] = gap2;
    const double tolerance2 = 1e-26 * scale2;
    io->certified[l] = int(moved_p <= tolerance2 || moved_y <= tolerance2) & int(gap2 > 1e-24 * scale2);
  }
}

/// A separated pair in A's frame (p of A, q of B, gap = q - p with gap2 = |gap|^2 > 0) as the result in the
/// cell frame.
inline SignedDistance separated_in_cell(const Obb& a, const double* p, const double* q, const double* gap,
                                        double gap2) {
  const double* Ra = a.rotation.data();
  SignedDistance out;
  out.distance = std::sqrt(gap2);
  const double inverse = 1.0 / out.distance;
  const double n[3] = {gap[0] * inverse, gap[1] * inverse, gap[2] * inverse};
  for (int i = 0; i < 3; ++i) {
    out.point_a[i] = a.center[i] + (Ra[i] * p[0] + Ra[i + 3] * p[1] + Ra[i + 6] * p[2]);
    out.point_b[i] = a.center[i] + (Ra[i] * q[0] + Ra[i + 3] * q[1] + Ra[i + 6] * q[2]);
    out.normal[i] = Ra[i] * n[0] + Ra[i + 3] * n[1] + Ra[i + 6] * n[2];
  }
  return out;
}

/// Lane l of a certified projection as the separated pair's result in the cell frame.
template <int L>
inline SignedDistance separated_lane(const Obb& a, const ProjectionLanes<L>& lanes, int l) {
  const double p[3] = {lanes.p[0][l], lanes.p[1][l], lanes.p[2][l]};
  const double q[3] = {lanes.q[0][l], lanes.q[1][l], lanes.q[2][l]};
  const double gap[3] = {lanes.gap[0][l], lanes.gap[1][l], lanes.gap[2][l]};
  return separated_in_cell(a, p, q, gap, lanes.gap2[l]);
}

}  // namespace cellmap::collision
