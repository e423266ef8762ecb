// SPDX-License-Identifier: Apache-2.0
#include "signed_distance.hpp"

#include <algorithm>
#include <cmath>

#include "closest_features.hpp"
#include "mutual_projections.hpp"
#include "projection_lanes.hpp"

namespace cellmap::collision {
namespace {

using Eigen::Vector3d;

// |ha|^2 + |hb|^2 + |t|^2: the scene size the tolerances scale with.
double scale2_of(const Vector3d& ha, const Vector3d& hb, const RelativePose& rel) {
  return ha.squaredNorm() + hb.squaredNorm() + rel.t.squaredNorm();
}

// The separation of the boxes along the unit direction n (A's frame), a lower bound of their distance:
// n.t minus the reach of A and of B along n.
double separation_along(const double* ha, const double* hb, const double* R, const double* t,
                        const double* n) {
  double separation = n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
  for (int k = 0; k < 3; ++k) {
    separation -= ha[k] * std::abs(n[k]) +
                  hb[k] * std::abs(R[3 * k] * n[0] + R[3 * k + 1] * n[1] + R[3 * k + 2] * n[2]);
  }
  return separation;
}

// A's point p and B's point q (A's frame), certified mutually closest by the projections, as a closest pair
// `distance2` apart. The projections certify to their step tolerance only: between nearly parallel features
// they creep by steps of the order of the angle, and the pair can then be off by up to ~1e-13 scale^2 /
// distance. So pairs nearer than kClearlySeparated (relative to the scene size, where that stays below
// ~1e-11 m) must also reach the separation along their own direction; nearer than kTouching the direction
// is rounding, and the separating axes decide instead.
constexpr double kClearlySeparated2 = 1e-6;
constexpr double kTouching2 = 1e-24;
bool near_pair_certified(const double* ha, const double* hb, const double* R, const double* t, double scale2,
                         const double* gap, double distance2) {
  if (!(distance2 > kTouching2 * scale2)) return false;
  const double distance = std::sqrt(distance2);
  const double n[3] = {gap[0] / distance, gap[1] / distance, gap[2] / distance};
  return distance - separation_along(ha, hb, R, t, n) <= 1e-10 * std::sqrt(scale2);
}
inline bool certified_apart(const double* ha, const double* hb, const double* R, const double* t,
                            double scale2, const double* gap, double* distance2) {
  *distance2 = gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2];
  return *distance2 > kClearlySeparated2 * scale2 ||
         near_pair_certified(ha, hb, R, t, scale2, gap, *distance2);
}

}  // namespace

bool clearly_separated(const Vector3d& ha, const Vector3d& hb, const RelativePose& rel, GjkResult* result) {
  const double scale2 = scale2_of(ha, hb, rel);
  double p[3], q[3], distance2;
  if (!mutually_closest_points(ha, hb, rel, scale2, p, q)) return false;
  const double gap[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
  if (!certified_apart(ha.data(), hb.data(), rel.R.data(), rel.t.data(), scale2, gap, &distance2))
    return false;
  result->point_a = Vector3d(p[0], p[1], p[2]);
  result->point_b = Vector3d(q[0], q[1], q[2]);
  result->distance = std::sqrt(distance2);
  return true;
}

GjkResult separated_distance(const Vector3d& ha, const Vector3d& hb, const RelativePose& rel,
                             const SeparatingAxis& axis) {
  GjkResult result;
  if (certify_by_axis(ha, hb, rel, axis, &result.point_a, &result.point_b)) {
    result.distance = (result.point_b - result.point_a).norm();
    return result;
  }
  return gjk(ha, hb, rel, nullptr, &axis.axis);
}

SignedDistance penetration_witnesses(const Obb& a, const Obb& b, const RelativePose& rel, double depth,
                                     const Vector3d& axis_a) {
  const double clearance = std::max(a.half_extents.norm() + b.half_extents.norm(), 1e-3);
  const double shift = depth + clearance;
  RelativePose moved = rel;
  moved.t += shift * axis_a;
  GjkResult g;
  if (!clearly_separated(a.half_extents, b.half_extents, moved, &g)) {
    SeparatingAxis axis = best_separating_axis(a.half_extents, b.half_extents, moved);
    if (!(axis.gap > 0.0)) {  // rounding; GJK decides below
      axis = SeparatingAxis{clearance, axis_a, SeparatingAxis::kFaceA, 0, 0};
    }
    g = separated_distance(a.half_extents, b.half_extents, moved, axis);
  }
  Vector3d pa = g.point_a;
  Vector3d pb = g.point_b - shift * axis_a;
  if (g.intersecting) {  // cannot happen for a true separating direction; stay finite regardless
    pa = Vector3d::Zero();
    pb = -depth * axis_a;
  }
  SignedDistance out;
  out.distance = -depth;
  out.point_a = a.rotation * pa + a.center;
  out.point_b = a.rotation * pb + a.center;
  out.normal = a.rotation * axis_a;
  return out;
}

namespace {

// The separating axes and GJK, for pairs the projections leave open (touching, overlapping, slow to
// converge).
SignedDistance signed_distance_by_axes(const Obb& a, const Obb& b, const RelativePose& rel) {
  const SeparatingAxis axis = best_separating_axis(a.half_extents, b.half_extents, rel);
  if (axis.gap > 0.0) {
    const GjkResult g = separated_distance(a.half_extents, b.half_extents, rel, axis);
    const Vector3d gap = g.point_b - g.point_a;
    const double distance2 = gap.squaredNorm();
    if (!g.intersecting && distance2 > 0.0) {
      return separated_in_cell(a, g.point_a.data(), gap.data(), distance2);
    }
  }
  // Touching (within rounding) or overlapping: the separating axes give the exact depth and its normal.
  return penetration_witnesses(a, b, rel, std::max(-axis.gap, 0.0), axis.axis);
}

// The pairs project_twice leaves open: the rounds of projections from where it left them (mostly one round:
// crossing edges in closed form), then the separating axes and GJK.
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline SignedDistance
open_pairs(const Obb& a, const Obb& b, const ProjectionLanes<double>& projection) {
  double p[3] = {projection.p[0], projection.p[1], projection.p[2]};
  double y[3] = {projection.y[0], projection.y[1], projection.y[2]};
  double q[3];
  const double* ha = a.half_extents.data();
  const double* hb = b.half_extents.data();
  if (mutually_closest_points_from(ha, hb, projection.R, projection.t, projection.scale2, p, y, q)) {
    const double gap[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    double distance2;
    if (certified_apart(ha, hb, projection.R, projection.t, projection.scale2, gap, &distance2)) {
      return separated_in_cell(a, p, gap, distance2);
    }
  }
  RelativePose rel;
  std::copy(projection.R, projection.R + 9, rel.R.data());
  std::copy(projection.t, projection.t + 3, rel.t.data());
  return signed_distance_by_axes(a, b, rel);
}

using OpenPairs = SignedDistance (*)(const Obb&, const Obb&, const ProjectionLanes<double>&);

// project_twice, then `open` for the pairs it leaves open (out of line: the certified pairs' path stays
// short).
template <OpenPairs open>
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline SignedDistance
project_then(const Obb& a, const Obb& b) {
  ProjectionLanes<double> projection;
  project_twice(view_of(a), view_of(b), &projection);
  if (projection.certified[0]) return separated_in_cell(a, projection.p, projection.gap, projection.gap2);
  return open(a, b, projection);
}

#if defined(__GNUC__)
__attribute__((noinline))
#endif
SignedDistance
open_pairs_baseline(const Obb& a, const Obb& b, const ProjectionLanes<double>& projection) {
  return open_pairs(a, b, projection);
}

// The same code compiled for AVX as well, chosen at run time: its three-operand instructions spare most of
// the register copies that SSE2's two-operand ones need (≈ 4 % per query on random pairs). Without FMA the
// arithmetic is the same, so both give the same bits.
#if defined(__x86_64__) && defined(__GNUC__)
#define CELLMAP_AVX_VARIANT 1
__attribute__((noinline, target("avx"))) SignedDistance open_pairs_avx(
    const Obb& a, const Obb& b, const ProjectionLanes<double>& projection) {
  return open_pairs(a, b, projection);
}

__attribute__((target("avx"))) SignedDistance signed_distance_avx(const Obb& a, const Obb& b) {
  return project_then<open_pairs_avx>(a, b);
}

bool cpu_has_avx() {
  __builtin_cpu_init();  // static initialisers may run before libgcc's own call of it
  return __builtin_cpu_supports("avx");
}
// False, so the baseline, for a caller in another file's static initialiser that runs before this one.
const bool kCpuHasAvx = cpu_has_avx();
#endif

}  // namespace

SignedDistance signed_distance_baseline(const Obb& a, const Obb& b) {
  return project_then<open_pairs_baseline>(a, b);
}

SignedDistance signed_distance(const Obb& a, const Obb& b) {
#if defined(CELLMAP_AVX_VARIANT)
  if (kCpuHasAvx) return signed_distance_avx(a, b);
#endif
  return signed_distance_baseline(a, b);
}

}  // namespace cellmap::collision
