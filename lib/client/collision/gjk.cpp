// SPDX-License-Identifier: Apache-2.0
#include "gjk.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "signed_volumes.hpp"

namespace cellmap::collision {
namespace {

using Eigen::Vector3d;

// Keeps the sub-simplex `sub` of `simplex` (indices come in increasing order, so compacting in place is
// safe).
void keep(const SubSimplex& sub, Simplex* simplex) {
  for (int i = 0; i < sub.n; ++i) {
    if (sub.index[i] != i) simplex->v[i] = simplex->v[sub.index[i]];
    simplex->lambda[i] = sub.lambda[i];
  }
  simplex->n = sub.n;
}

bool in_simplex(const Simplex& simplex, const SupportVertex& w) {
  for (int i = 0; i < simplex.n; ++i) {
    if (simplex.v[i].id == w.id) return true;
  }
  return false;
}

Vector3d closest_point(const Simplex& simplex, const SubSimplex& sub) {
  Vector3d v = sub.lambda[0] * simplex.v[sub.index[0]].w;
  for (int i = 1; i < sub.n; ++i) v += sub.lambda[i] * simplex.v[sub.index[i]].w;
  return v;
}

// The points of A and B (A's frame) whose difference is the simplex's closest point.
void witness_points(const Simplex& simplex, const Vector3d& ha, GjkResult* result) {
  result->point_a = Vector3d::Zero();
  result->point_b = Vector3d::Zero();
  for (int i = 0; i < simplex.n; ++i) {
    const Vector3d a = vertex_of_a(simplex.v[i].id, ha);
    result->point_a += simplex.lambda[i] * a;
    result->point_b += simplex.lambda[i] * (a - simplex.v[i].w);
  }
}

}  // namespace

GjkResult gjk(const Vector3d& ha, const Vector3d& hb, const RelativePose& rel, Simplex* simplex_out,
              const Vector3d* towards_b) {
  const MinkowskiSupport support{ha, hb, rel};
  // (|ha| + |hb| + |t|)^2 <= 3 (|ha|^2 + |hb|^2 + |t|^2): a scene size without square roots.
  const double scale2 = 3.0 * (ha.squaredNorm() + hb.squaredNorm() + rel.t.squaredNorm());
  const double tiny2 = std::max(1e-24 * scale2, std::numeric_limits<double>::min());
  constexpr double kRelative = 1e-14;
  constexpr int kMaxIterations = 64;

  Simplex simplex;
  // From a direction A → B the first support point lies towards the origin.
  Vector3d v = towards_b != nullptr ? Vector3d(-*towards_b) : Vector3d(-rel.t);
  if (!(v.squaredNorm() > tiny2)) v = Vector3d(1.0, 0.0, 0.0) * std::max(std::sqrt(scale2), 1.0);
  double vv = std::numeric_limits<double>::infinity();
  GjkResult result;
  for (; result.iterations < kMaxIterations; ++result.iterations) {
    const SupportVertex w = support(-v);
    if (in_simplex(simplex, w)) break;
    if (simplex.n > 0 && vv - v.dot(w.w) <= kRelative * vv) break;
    // Tentatively append w; the simplex is only changed for good when the distance decreases.
    simplex.v[simplex.n] = w;
    const SubSimplex sub = closest_to_origin(simplex.v, simplex.n + 1);
    if (sub.n == 4) {
      keep(sub, &simplex);
      result.intersecting = true;
      break;
    }
    const Vector3d v_next = closest_point(simplex, sub);
    const double vv_next = v_next.squaredNorm();
    if (simplex.n > 0 && !(vv_next < vv))
      break;  // no progress: rounding floor reached, keep the last simplex
    keep(sub, &simplex);
    v = v_next;
    vv = vv_next;
    if (vv <= tiny2) {
      result.intersecting = true;
      break;
    }
  }
  witness_points(simplex, ha, &result);
  result.distance = result.intersecting ? 0.0 : std::sqrt(std::max(vv, 0.0));
  if (simplex_out != nullptr) *simplex_out = simplex;
  return result;
}

GjkResult gjk_distance(const Obb& a, const Obb& b) {
  GjkResult result = gjk(a.half_extents, b.half_extents, relative_pose(a, b));
  result.point_a = a.rotation * result.point_a + a.center;
  result.point_b = a.rotation * result.point_b + a.center;
  return result;
}

}  // namespace cellmap::collision
