// SPDX-License-Identifier: Apache-2.0
#pragma once
// Volumes of box overlaps: how much of one box lies inside another, exactly (fidelity is measured by volume).

#include "cellmap/boxes/box.hpp"

namespace cellmap {

/// Volume (m³) of the common part of two oriented boxes, exact up to rounding: box a, as a convex polyhedron,
/// is clipped by the six face planes of box b and the volume of what remains is summed from tetrahedra.
/// Symmetric up to rounding; 0 for disjoint or degenerate boxes. Pure, thread-safe, about 2 µs.
/// Hand-written: neither Eigen, PCL nor FCL computes the overlap volume of two boxes (FCL's collide returns
/// contact points, not volumes).
[[nodiscard]] double intersection_volume(const Box& a, const Box& b);

/// Volumetric intersection over union, intersection_volume / (volume(a) + volume(b) − intersection), in
/// [0, 1]; 0 when both boxes are empty.
[[nodiscard]] double volume_iou(const Box& a, const Box& b);

}  // namespace cellmap
