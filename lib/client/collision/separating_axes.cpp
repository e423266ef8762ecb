// SPDX-License-Identifier: Apache-2.0
#include "separating_axes.hpp"

namespace cellmap::collision {

SignedDistance separating_axis_depth(const Obb& a, const Obb& b) {
  const SeparatingAxis sat = best_separating_axis(a.half_extents, b.half_extents, relative_pose(a, b));
  SignedDistance out;
  out.distance = sat.gap;
  out.normal = a.rotation * sat.axis;
  return out;
}

}  // namespace cellmap::collision
