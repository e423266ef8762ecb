// SPDX-License-Identifier: Apache-2.0
#include "closest_features.hpp"

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

}  // namespace cellmap::collision
