#include "signed_distance.hpp"

#include <algorithm>
#include <cmath>

#include "closest_features.hpp"

namespace cellmap::collision {
namespace {

using Eigen::Vector3d;

// A separated pair's result in the cell frame.
SignedDistance separated_result(const Obb& a, const GjkResult& g, const Vector3d& axis) {
  SignedDistance out;
  out.distance = g.distance;
  out.point_a = a.rotation * g.point_a + a.center;
  out.point_b = a.rotation * g.point_b + a.center;
  // A positive separation exceeds the rounding floor, so the direction is well defined; a certified pair at
  // zero distance cannot occur (the axis gap is positive), the fallback only guards against rounding.
  const Vector3d gap = g.point_b - g.point_a;
  out.normal = a.rotation * (gap.squaredNorm() > 0.0 ? Vector3d(gap.normalized()) : axis);
  return out;
}

}  // namespace

bool clearly_separated(const Vector3d& ha, const Vector3d& hb, const RelativePose& rel, GjkResult* result) {
  if (!mutually_closest_points(ha, hb, rel, &result->point_a, &result->point_b)) return false;
  const double distance2 = (result->point_b - result->point_a).squaredNorm();
  if (!(distance2 > 1e-24 * (ha.squaredNorm() + hb.squaredNorm() + rel.t.squaredNorm()))) return false;
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

SignedDistance signed_distance(const Obb& a, const Obb& b) {
  const RelativePose rel = relative_pose(a, b);
  const Vector3d& ha = a.half_extents;
  const Vector3d& hb = b.half_extents;
  GjkResult g;
  if (clearly_separated(ha, hb, rel, &g)) return separated_result(a, g, Vector3d::UnitX());
  // Slowly converging, touching or overlapping: the separating axes decide.
  const SeparatingAxis axis = best_separating_axis(ha, hb, rel);
  if (axis.gap > 0.0) {
    const GjkResult g = separated_distance(ha, hb, rel, axis);
    if (!g.intersecting) return separated_result(a, g, axis.axis);
  }
  // Touching (within rounding) or overlapping: the separating axes give the exact depth and its normal.
  return penetration_witnesses(a, b, rel, std::max(-axis.gap, 0.0), axis.axis);
}

}  // namespace cellmap::collision
