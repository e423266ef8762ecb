// SPDX-License-Identifier: Apache-2.0
#include "signed_volumes.hpp"

namespace cellmap::collision {
namespace {

using Eigen::Vector3d;
using Points = std::array<SupportVertex, 4>;

SubSimplex closest_vertex(const Points& s, int i) {
  SubSimplex r;
  r.index[0] = i;
  r.lambda[0] = 1.0;
  r.n = 1;
  r.distance2 = s[i].w.squaredNorm();
  return r;
}

SubSimplex closest_segment(const Points& s, int i0, int i1) {
  const Vector3d& p0 = s[i0].w;
  const Vector3d& p1 = s[i1].w;
  const Vector3d u = p1 - p0;
  const double uu = u.squaredNorm();
  if (!(uu > 0.0)) return closest_vertex(s, p0.squaredNorm() <= p1.squaredNorm() ? i0 : i1);
  const double along = -p0.dot(u);
  if (along <= 0.0) return closest_vertex(s, i0);
  if (along >= uu) return closest_vertex(s, i1);
  SubSimplex r;
  r.n = 2;
  r.index[0] = i0;
  r.index[1] = i1;
  r.lambda[1] = along / uu;
  r.lambda[0] = 1.0 - r.lambda[1];
  r.distance2 = (p0 + r.lambda[1] * u).squaredNorm();
  return r;
}

// Edge of a triangle, vertex indices in increasing order (the GJK loop compacts the simplex in place).
SubSimplex closest_edge(const Points& s, int i, int j) {
  return i < j ? closest_segment(s, i, j) : closest_segment(s, j, i);
}

// The closest point lies on one of the triangle's edges: on those the origin's projection is outside of
// (all three when `outside` is null, for a degenerate triangle).
SubSimplex closest_on_edges(const Points& s, const std::array<int, 3>& idx, const bool* outside) {
  SubSimplex best;
  for (int j = 0; j < 3; ++j) {
    if (outside != nullptr && !outside[j]) continue;
    const SubSimplex edge = closest_edge(s, idx[(j + 1) % 3], idx[(j + 2) % 3]);
    if (edge.distance2 < best.distance2) best = edge;
  }
  return best;
}

double cross2(double ax, double ay, double bx, double by) {
  return ax * by - ay * bx;
}

SubSimplex closest_triangle(const Points& s, int i0, int i1, int i2) {
  const std::array<int, 3> idx{i0, i1, i2};
  const Vector3d& p0 = s[i0].w;
  const Vector3d& p1 = s[i1].w;
  const Vector3d& p2 = s[i2].w;
  const Vector3d n = (p1 - p0).cross(p2 - p0);
  const double nn = n.squaredNorm();
  const double scale = (p1 - p0).squaredNorm() * (p2 - p0).squaredNorm();
  if (!(nn > 1e-28 * scale && nn > 0.0)) return closest_on_edges(s, idx, nullptr);  // collinear
  // Project the origin onto the plane, then measure signed areas in the coordinate plane where the
  // triangle's projection is largest (the component of n with the largest magnitude).
  const Vector3d po = n * (n.dot(p0) / nn);
  int k = 0;
  n.cwiseAbs().maxCoeff(&k);
  const int x = (k + 1) % 3;
  const int y = (k + 2) % 3;
  const double mu = n[k];
  const std::array<const Vector3d*, 3> p{&p0, &p1, &p2};
  std::array<double, 3> c{};
  bool outside[3];
  bool inside = true;
  for (int j = 0; j < 3; ++j) {
    const Vector3d& q1 = *p[(j + 1) % 3];
    const Vector3d& q2 = *p[(j + 2) % 3];
    c[j] = cross2(q1[x] - po[x], q1[y] - po[y], q2[x] - po[x], q2[y] - po[y]);
    outside[j] = !(c[j] * mu > 0.0);  // the projection is beyond the edge opposite j
    inside = inside && !outside[j];
  }
  if (!inside) return closest_on_edges(s, idx, outside);
  SubSimplex best;
  best.n = 3;
  for (int j = 0; j < 3; ++j) {
    best.index[j] = idx[j];
    best.lambda[j] = c[j] / mu;
  }
  best.distance2 = po.squaredNorm();
  return best;
}

double volume(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a));
}

// Returns n = 4 (origin inside) or the closest face/edge/vertex.
SubSimplex closest_tetrahedron(const Points& s) {
  const Vector3d& p0 = s[0].w;
  const Vector3d& p1 = s[1].w;
  const Vector3d& p2 = s[2].w;
  const Vector3d& p3 = s[3].w;
  const Vector3d zero = Vector3d::Zero();
  const double total = volume(p0, p1, p2, p3);
  const double scale2 = (p1 - p0).squaredNorm() * (p2 - p0).squaredNorm() * (p3 - p0).squaredNorm();
  const std::array<double, 4> c{volume(zero, p1, p2, p3), volume(p0, zero, p2, p3), volume(p0, p1, zero, p3),
                                volume(p0, p1, p2, zero)};
  const bool degenerate = !(total * total > 1e-28 * scale2);
  SubSimplex best;
  if (!degenerate && c[0] * total > 0.0 && c[1] * total > 0.0 && c[2] * total > 0.0 && c[3] * total > 0.0) {
    best.n = 4;
    for (int j = 0; j < 4; ++j) {
      best.index[j] = j;
      best.lambda[j] = c[j] / total;
    }
    best.distance2 = 0.0;
    return best;
  }
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (int j = 0; j < 4; ++j) {
    if (!degenerate && c[j] * total > 0.0) continue;
    const SubSimplex face = closest_triangle(s, kFace[j][0], kFace[j][1], kFace[j][2]);
    if (face.distance2 < best.distance2) best = face;
  }
  return best;
}

}  // namespace

SubSimplex closest_to_origin(const std::array<SupportVertex, 4>& s, int n) {
  switch (n) {
    case 1:
      return closest_vertex(s, 0);
    case 2:
      return closest_segment(s, 0, 1);
    case 3:
      return closest_triangle(s, 0, 1, 2);
    default:
      return closest_tetrahedron(s);
  }
}

}  // namespace cellmap::collision
