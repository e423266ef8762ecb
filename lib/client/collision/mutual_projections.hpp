// SPDX-License-Identifier: Apache-2.0
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

// The feature of a box holding a point on its surface: bit k set when |x_k| < h_k (coordinate k free).
// An edge point has one free coordinate, a face point two.
inline int free_coordinates(const double* x, const double* h) {
  return int(std::abs(x[0]) < h[0]) | int(std::abs(x[1]) < h[1]) << 1 | int(std::abs(x[2]) < h[2]) << 2;
}
// The free coordinate of an edge point, the fixed coordinate of a face point (-1: not that feature).
inline constexpr int kEdgeDirection[8] = {-1, 0, 1, -1, 2, -1, -1, -1};
inline constexpr int kFaceNormal[8] = {-1, -1, -1, 2, -1, 1, 0, -1};

// Below this |cos| (resp. sin^2) an edge counts as parallel to a face (resp. an edge). An edge parallel to a
// face projects onto it in one step. Two nearly parallel edges do not: the projections creep along them by
// steps of the order of the angle, too small for the certificate to tell from convergence, so such pairs are
// left to the separating axes.
inline constexpr double kParallel = 1e-9;

// x on an edge of its box (free coordinate k, half extent h) facing the other box's face, whose outward
// normal has component `slope` along the edge: x_k moves to the edge's end nearest the face plane, unless
// parallel.
inline bool step_to_edge_end(double slope, double h, int k, double* x) {
  if (!(std::abs(slope) > kParallel)) return false;
  const double end = slope > 0.0 ? -h : h;
  for (int m = 0; m < 3; ++m) x[m] = m == k ? end : x[m];
  return true;
}

// p on A's edge along e_i, y on B's edge along R.col(j): both move to the closest points of the two edges
// (segments), in closed form: B's parameter on the lines, clamped; A's for it, clamped; B's again for that,
// clamped (exact for segments). Writes B's new point in A's frame to q. Returns false, moving nothing, for
// (nearly) parallel edges.
inline bool move_to_crossing_edges(const double* ha, const double* hb, const double* R, const double* t,
                                   int i, int j, double* p, double* y, double* q) {
  const double* d = R + 3 * j;  // B's edge direction in A's frame
  const double c = d[i];
  const double sin2 = 1.0 - c * c;
  if (!(sin2 > kParallel)) return false;
  const double inverse_sin2 = 1.0 / sin2;  // divided while the numerator is computed, not after it
  // Lines a0 + s e_i (a0 = p with p_i = 0) and b0 + u d (b0 = B's edge centre); r = a0 - b0. Selects rather
  // than stores at index i or j keep the numbers in registers.
  double y0[3];
  for (int k = 0; k < 3; ++k) y0[k] = k == j ? 0.0 : y[k];
  double b0[3], r[3];
  b_to_a(R, t, y0, b0);
  for (int k = 0; k < 3; ++k) r[k] = (k == i ? 0.0 : p[k]) - b0[k];
  const double dr = d[0] * r[0] + d[1] * r[1] + d[2] * r[2];
  const double u_lines = clamp((dr - c * r[i]) * inverse_sin2, hb[j]);
  const double s = clamp(u_lines * c - r[i], ha[i]);
  const double u = clamp(dr + s * c, hb[j]);
  for (int k = 0; k < 3; ++k) p[k] = k == i ? s : p[k];
  for (int k = 0; k < 3; ++k) y[k] = k == j ? u : y[k];
  for (int k = 0; k < 3; ++k) q[k] = b0[k] + u * d[k];
  return true;
}

// One round from A's point p and B's point y closest to it (B's coordinates). First the jumps, in closed
// form, where plain projections would zig-zag: p and y on two crossing edges move to the closest points of
// those edges, p on an edge facing B's face (or y on an edge facing A's face) to the edge's end nearest that
// face; y follows p as B's point closest to it. Then p' = A's point closest to y (q = y in A's frame) and y'
// = B's point closest to p'. Mutually closest when y is B's point closest to p and p' repeats p, or y'
// repeats y: returns kMutuallyClosest with p' in p and q. Else p = p', y = y' for the next round, or
// kParallelEdges.
enum class Round { kMutuallyClosest, kNext, kParallelEdges };
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline Round
projection_round(const double* ha, const double* hb, const double* R, const double* t, double tolerance2,
                 double* p, double* y, double* q) {
  const int p_free = free_coordinates(p, ha);
  const int y_free = free_coordinates(y, hb);
  const int i = kEdgeDirection[p_free];
  const int j = kEdgeDirection[y_free];
  bool y_fits = true;    // y is B's point closest to p
  bool q_ready = false;  // q already holds y in A's frame
  if (i >= 0 && j >= 0) {
    if (!move_to_crossing_edges(ha, hb, R, t, i, j, p, y, q)) return Round::kParallelEdges;
    // The closest points of the edges are mostly B's point closest to p already: then the jump's q serves,
    // and the step onto A need not wait for B's closest point to be moved to A's frame.
    double y_closest[3];
    closest_in_b(R, t, hb, p, y_closest);
    q_ready = distance2(y_closest, y) <= tolerance2;
    std::copy(y_closest, y_closest + 3, y);
  } else if (i >= 0 && kFaceNormal[y_free] >= 0) {
    const int face = kFaceNormal[y_free];  // B's face normal in A's frame: sign(y_face) R.col(face)
    if (y[face] != 0.0 && step_to_edge_end(y[face] > 0.0 ? R[i + 3 * face] : -R[i + 3 * face], ha[i], i, p))
      closest_in_b(R, t, hb, p, y);
  } else if (j >= 0 && kFaceNormal[p_free] >= 0) {
    const int face = kFaceNormal[p_free];  // A's face normal: sign(p_face) e_face
    y_fits = !(p[face] != 0.0 &&
               step_to_edge_end(p[face] > 0.0 ? R[face + 3 * j] : -R[face + 3 * j], hb[j], j, y));
  }
  if (!q_ready) b_to_a(R, t, y, q);
  double p_next[3];
  closest_in_a(ha, q, p_next);
  if (y_fits && distance2(p_next, p) <= tolerance2) return Round::kMutuallyClosest;
  std::copy(p_next, p_next + 3, p);
  double y_next[3];
  closest_in_b(R, t, hb, p, y_next);
  if (distance2(y_next, y) <= tolerance2) return Round::kMutuallyClosest;
  std::copy(y_next, y_next + 3, y);
  return Round::kNext;
}

}  // namespace mutual_projections_detail

/// Mutually closest points: from A's point p and B's point y closest to it (B's coordinates, R and t as in
/// RelativePose, column-major), rounds of projections onto A and back onto B, jumping ahead where an edge
/// faces an edge or a face (see projection_round). When each point is the other's closest point (to 1e-13 of
/// the scene size, `scale2` = |ha|^2 + |hb|^2 + |t|^2), they are a closest pair (mutually closest points of
/// two convex sets are: the direction between them lies in both normal cones). Updates p and y, writes B's
/// point q (A's frame) and returns true when that happened within a few rounds; overlapping boxes end on a
/// common point.
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline bool
mutually_closest_points_from(const double* ha, const double* hb, const double* R, const double* t,
                             double scale2, double* p, double* y, double* q) {
  constexpr int kRounds = 4;
  for (int round = 0; round < kRounds; ++round) {
    using mutual_projections_detail::Round;
    const Round outcome = mutual_projections_detail::projection_round(ha, hb, R, t, 1e-26 * scale2, p, y, q);
    if (outcome != Round::kNext) return outcome == Round::kMutuallyClosest;
  }
  return false;
}

/// As above, starting from A's point closest to B's centre (~99 % of random separated pairs converge).
inline bool mutually_closest_points(const Eigen::Vector3d& ha, const Eigen::Vector3d& hb,
                                    const RelativePose& rel, double scale2, double* p, double* q) {
  using namespace mutual_projections_detail;
  double y[3];
  closest_in_a(ha.data(), rel.t.data(), p);
  closest_in_b(rel.R.data(), rel.t.data(), hb.data(), p, y);
  return mutually_closest_points_from(ha.data(), hb.data(), rel.R.data(), rel.t.data(), scale2, p, y, q);
}

}  // namespace cellmap::collision
