#include "closest_features.hpp"

#include <algorithm>
#include <cmath>

namespace cellmap::collision {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// B's vertex deepest towards A's face i must project into that face.
bool certify_face_of_a(const Vector3d& ha, const Vector3d& hb, const RelativePose& rel,
                       const SeparatingAxis& axis, Vector3d* pa, Vector3d* pb) {
  const Matrix3d& R = rel.R;
  const int i = axis.i;
  const double s = axis.axis[i];
  const Vector3d sigma(sign_of(-s * R(i, 0)), sign_of(-s * R(i, 1)), sign_of(-s * R(i, 2)));
  const Vector3d v = rel.t + R * sigma.cwiseProduct(hb);
  const int k1 = (i + 1) % 3, k2 = (i + 2) % 3;
  if (std::abs(v[k1]) > ha[k1] || std::abs(v[k2]) > ha[k2]) return false;
  *pb = v;
  *pa = v;
  (*pa)[i] = s * ha[i];
  return true;
}

// A's vertex deepest towards B's face j must project into that face (tested in B's frame).
bool certify_face_of_b(const Vector3d& ha, const Vector3d& hb, const RelativePose& rel,
                       const SeparatingAxis& axis, Vector3d* pa, Vector3d* pb) {
  const Matrix3d& R = rel.R;
  const int j = axis.j;
  const double s = sign_of(axis.axis.dot(R.col(j)));
  const Vector3d u =
      Vector3d(sign_of(s * R(0, j)), sign_of(s * R(1, j)), sign_of(s * R(2, j))).cwiseProduct(ha);
  Vector3d u_B = R.transpose() * (u - rel.t);
  const int k1 = (j + 1) % 3, k2 = (j + 2) % 3;
  if (std::abs(u_B[k1]) > hb[k1] || std::abs(u_B[k2]) > hb[k2]) return false;
  *pa = u;
  u_B[j] = -s * hb[j];
  *pb = rel.t + R * u_B;
  return true;
}

// A's edge along e_i and B's edge along R.col(j), the ones extreme along the axis: their common
// perpendicular must meet both.
bool certify_edges(const Vector3d& ha, const Vector3d& hb, const RelativePose& rel,
                   const SeparatingAxis& axis, Vector3d* pa, Vector3d* pb) {
  const Matrix3d& R = rel.R;
  const int i = axis.i;
  const int j = axis.j;
  const Vector3d& L = axis.axis;
  Vector3d a0(sign_of(L[0]) * ha[0], sign_of(L[1]) * ha[1], sign_of(L[2]) * ha[2]);
  a0[i] = 0.0;
  const Vector3d L_B = R.transpose() * L;
  Vector3d b_local(sign_of(-L_B[0]) * hb[0], sign_of(-L_B[1]) * hb[1], sign_of(-L_B[2]) * hb[2]);
  b_local[j] = 0.0;
  const Vector3d b0 = rel.t + R * b_local;
  const Vector3d d2 = R.col(j);
  const Vector3d r = a0 - b0;
  const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
  const double a12 = R(i, j);
  const double c1 = r[i];
  const double c2 = d2.dot(r);
  const double alpha = (a12 * c2 - c1) / (R(i1, j) * R(i1, j) + R(i2, j) * R(i2, j));  // = 1 - a12^2 > 1e-16
  const double beta = c2 + alpha * a12;
  if (std::abs(alpha) > ha[i] || std::abs(beta) > hb[j]) return false;
  *pa = a0;
  (*pa)[i] += alpha;
  *pb = b0 + beta * d2;
  return true;
}

}  // namespace

bool certify_by_axis(const Vector3d& ha, const Vector3d& hb, const RelativePose& rel,
                     const SeparatingAxis& axis, Vector3d* pa, Vector3d* pb) {
  switch (axis.kind) {
    case SeparatingAxis::kFaceA:
      return certify_face_of_a(ha, hb, rel, axis, pa, pb);
    case SeparatingAxis::kFaceB:
      return certify_face_of_b(ha, hb, rel, axis, pa, pb);
    default:
      return certify_edges(ha, hb, rel, axis, pa, pb);
  }
}

namespace {

// The hot loop on plain numbers (Eigen's 3-vectors are not vectorised and its temporaries cost here).
// R column-major as Eigen stores it: R[i + 3 j] = R(i, j).

double clamp(double x, double h) {
  return std::min(std::max(x, -h), h);
}

// q = t + R y: B's point y (B's coordinates) in A's frame.
void b_to_a(const double* R, const double* t, const double* y, double* q) {
  for (int i = 0; i < 3; ++i) q[i] = t[i] + R[i] * y[0] + R[i + 3] * y[1] + R[i + 6] * y[2];
}

// y = clamp_B(R^T (p - t)): B's point closest to A's point p, in B's coordinates.
void closest_in_b(const double* R, const double* t, const double* hb, const double* p, double* y) {
  const double d[3] = {p[0] - t[0], p[1] - t[1], p[2] - t[2]};
  for (int j = 0; j < 3; ++j)
    y[j] = clamp(R[3 * j] * d[0] + R[3 * j + 1] * d[1] + R[3 * j + 2] * d[2], hb[j]);
}

// p = clamp_A(q): A's point closest to q.
void closest_in_a(const double* ha, const double* q, double* p) {
  for (int i = 0; i < 3; ++i) p[i] = clamp(q[i], ha[i]);
}

double distance2(const double* u, const double* v) {
  const double d0 = u[0] - v[0], d1 = u[1] - v[1], d2 = u[2] - v[2];
  return d0 * d0 + d1 * d1 + d2 * d2;
}

// The coordinate of p strictly inside the box (|p_k| < h_k) if exactly one is (p on an edge), else -1.
int edge_direction(const double* p, const double* h) {
  const int inside =
      int(std::abs(p[0]) < h[0]) | int(std::abs(p[1]) < h[1]) << 1 | int(std::abs(p[2]) < h[2]) << 2;
  static constexpr int kDirection[8] = {-1, 0, 1, -1, 2, -1, -1, -1};
  return kDirection[inside];
}

// When p lies on an edge of A and y on an edge of B: moves y to the point of its edge closest to A's edge
// line (clamped to the edge); returns false (y unchanged) otherwise or for nearly parallel edges.
bool step_to_crossing_edges(const double* ha, const double* hb, const double* R, const double* t,
                            const double* p, double* y) {
  const int i = edge_direction(p, ha);
  const int j = edge_direction(y, hb);
  if (i < 0 || j < 0) return false;
  const double* d = R + 3 * j;  // B's edge direction in A's frame
  const double c = d[i];
  const double sin2 = 1.0 - c * c;
  if (!(sin2 > 1e-12)) return false;
  // Lines a0 + alpha e_i (a0 = p with p_i = 0) and b0 + beta d (b0 = B's edge centre); r = a0 - b0.
  double y0[3] = {y[0], y[1], y[2]};
  y0[j] = 0.0;
  double r[3];
  b_to_a(R, t, y0, r);
  for (int k = 0; k < 3; ++k) r[k] = (k == i ? 0.0 : p[k]) - r[k];
  const double dr = d[0] * r[0] + d[1] * r[1] + d[2] * r[2];
  const double alpha = (c * dr - r[i]) / sin2;
  y[j] = clamp(dr + alpha * c, hb[j]);
  return true;
}

}  // namespace

bool mutually_closest_points(const Vector3d& ha_, const Vector3d& hb_, const RelativePose& rel, Vector3d* pa,
                             Vector3d* pb) {
  const double* ha = ha_.data();
  const double* hb = hb_.data();
  const double* R = rel.R.data();
  const double* t = rel.t.data();
  const double tolerance2 = 1e-26 * (ha_.squaredNorm() + hb_.squaredNorm() + rel.t.squaredNorm());
  constexpr int kSteps = 6;
  // From A's point closest to B's centre. Invariant after the first step: q = t + R y is a point of B and
  // p = clamp_A(q) the point of A closest to it.
  double y[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
  double q[3] = {0.0, 0.0, 0.0};
  double p[3];
  closest_in_a(ha, t, p);
  for (int step = 0;; ++step) {
    double y_next[3];
    closest_in_b(R, t, hb, p, y_next);
    if (distance2(y_next, y) <= tolerance2) break;  // q is B's point closest to p
    std::copy(y_next, y_next + 3, y);
    const bool jumped = step_to_crossing_edges(ha, hb, R, t, p, y);
    b_to_a(R, t, y, q);
    double p_next[3];
    closest_in_a(ha, q, p_next);
    const bool converged = !jumped && distance2(p_next, p) <= tolerance2;  // p_next is A's closest to q
    std::copy(p_next, p_next + 3, p);
    if (converged) break;
    if (step + 1 == kSteps) return false;
  }
  *pa = Vector3d(p[0], p[1], p[2]);
  *pb = Vector3d(q[0], q[1], q[2]);
  return true;
}

}  // namespace cellmap::collision
