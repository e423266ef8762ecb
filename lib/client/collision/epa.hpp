// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: EPA (expanding polytope) penetration depth, a general polytope algorithm kept as an independent
// cross-check of the separating-axis depth that signed_distance uses (exact and faster on boxes).

#include "cellmap/collision/box_distance.hpp"

namespace cellmap::collision {

/// Penetration depth and witness points of overlapping boxes (as SignedDistance, cell frame); for separated
/// boxes the GJK distance. Always finite.
[[nodiscard]] SignedDistance epa_penetration(const Obb& a, const Obb& b);

}  // namespace cellmap::collision
