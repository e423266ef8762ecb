#pragma once
// Internal: closest points of two boxes by alternating closest-point projections, the fast path of
// signed_distance. Inline so that the loop keeps its numbers in registers inside the caller.

#include <algorithm>
#include <cmath>

#include "relative_pose.hpp"

namespace cellmap::collision {

namespace mutual_projections_detail {

// Plain numbers (Eigen's 3-vectors are not vectorised and their temporaries cost here). R column-major as
// Eigen stores it: R[i + 3 j] = R(i, j).

inline double clamp(double x, double h) {
  return std::min(std::max(x, -h), h);
}

// q = t + R y: B's point y (B's coordinates) in A's frame.
inline void b_to_a(const double* R, const double* t, const double* y, double* q) {
  for (int i = 0; i < 3; ++i) q[i] = t[i] + R[i] * y[0] + R[i + 3] * y[1] + R[i + 6] * y[2];
}

// y = clamp_B(R^T (p - t)): B's point closest to A's point p, in B's coordinates.
inline void closest_in_b(const double* R, const double* t, const double* hb, const double* p, double* y) {
  const double d[3] = {p[0] - t[0], p[1] - t[1], p[2] - t[2]};
  for (int j = 0; j < 3; ++j)
    y[j] = clamp(R[3 * j] * d[0] + R[3 * j + 1] * d[1] + R[3 * j + 2] * d[2], hb[j]);
}

// p = clamp_A(q): A's point closest to q.
inline void closest_in_a(const double* ha, const double* q, double* p) {
  for (int i = 0; i < 3; ++i) p[i] = clamp(q[i], ha[i]);
}

inline double distance2(const double* u, const double* v) {
  const double d0 = u[0] - v[0], d1 = u[1] - v[1], d2 = u[2] - v[2];
  return d0 * d0 + d1 * d1 + d2 * d2;
}

// The steps where plain projections would zig-zag (mutual_projections.cpp). After B's point y was projected
// from A's point p: y on an edge of B facing A's edge goes to the closest points of the two edge lines; y on
// an edge facing A's face goes to the edge's end nearest that face. Return false when nothing moved.
bool jump_on_b(const double* ha, const double* hb, const double* R, const double* t, const double* p,
               double* y);
// After A's point p was projected from B's point y: p on an edge of A facing a face of B goes to the edge's
// end nearest that face.
bool jump_on_a(const double* ha, const double* hb, const double* R, const double* y, double* p);

}  // namespace mutual_projections_detail

/// Mutually closest points: from A's point p and B's point y closest to it (B's coordinates), project onto A,
/// back onto B, and so on, jumping ahead where an edge faces an edge or a face (see jump_on_b, jump_on_a).
/// When each point is the other's closest point (to 1e-13 of the scene size, `scale2` = |ha|^2 + |hb|^2 +
/// |t|^2), they are a closest pair (mutually closest points of two convex sets are: the direction between
/// them lies in both normal cones). Updates p and y, writes B's point q (A's frame) and returns true when
/// that happened within a few steps; overlapping boxes end on a common point.
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline bool
mutually_closest_points_from(const Eigen::Vector3d& ha_, const Eigen::Vector3d& hb_, const RelativePose& rel,
                             double scale2, double* p, double* y, double* q) {
  using namespace mutual_projections_detail;
  const double* ha = ha_.data();
  const double* hb = hb_.data();
  const double* R = rel.R.data();
  const double* t = rel.t.data();
  const double tolerance2 = 1e-26 * scale2;
  constexpr int kSteps = 6;
  // `y_fits`: y is B's point closest to p (false right after a jump); p is A's point closest to q unless it
  // just jumped.
  bool y_fits = !jump_on_b(ha, hb, R, t, p, y);
  for (int step = 0;; ++step) {
    b_to_a(R, t, y, q);
    double p_next[3];
    closest_in_a(ha, q, p_next);
    const bool p_converged = y_fits && distance2(p_next, p) <= tolerance2;
    std::copy(p_next, p_next + 3, p);
    if (p_converged) return true;
    if (step == kSteps) return false;
    const bool p_fits = !jump_on_a(ha, hb, R, y, p);
    double y_next[3];
    closest_in_b(R, t, hb, p, y_next);
    const bool y_converged = p_fits && distance2(y_next, y) <= tolerance2;
    std::copy(y_next, y_next + 3, y);
    if (y_converged) {
      b_to_a(R, t, y, q);
      return true;
    }
    y_fits = !jump_on_b(ha, hb, R, t, p, y);
  }
}

/// As above, starting from A's point closest to B's centre (~99 % of random separated pairs converge).
inline bool mutually_closest_points(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb,
                                    const RelativePose& rel, double scale2, double* p, double* q) {
  using namespace mutual_projections_detail;
  double y[3];
  closest_in_a(ha.data(), rel.t.data(), p);
  closest_in_b(rel.R.data(), rel.t.data(), hb.data(), p, y);
  return mutually_closest_points_from(ha, hb, rel, scale2, p, y, q);
}

}  // namespace cellmap::collision
