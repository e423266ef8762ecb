// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reconciling re-segmented boxes with the previous environment: stable ids, minimal deltas.

#include <cstdint>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/common/region.hpp"

namespace cellmap {

/// The axis-aligned bounds of an (oriented) box in the cell frame.
[[nodiscard]] Region bounds_of(const Box& box);

/// True if every corner of `inner` lies inside `outer` grown by `tolerance` (metres).
[[nodiscard]] bool box_inside(const Box& inner, const Box& outer, double tolerance);

struct ReconcileParams final {
  /// A new box takes an old box's id when the IoU of their bounds is at least this; else it is a new object.
  double min_overlap = 0.3;
  /// A matched box whose centre and half extents moved less than this (metres) and rotated less than
  /// `rotation_tolerance` (radians) keeps its old value exactly, so noise yields no delta.
  double position_tolerance = 0.02;
  double rotation_tolerance = 0.05;
  /// New boxes lying entirely inside a kept box, or inside a larger new box, grown by this (metres) are
  /// redundant and dropped: their points are already covered.
  double redundant_tolerance = 0.02;
};

/// Ids of the boxes of `previous` that contain at least one of `changed_C` (the centres of voxels whose state
/// changed, cell frame), and at least `min_share` · box.points of them: the boxes whose own evidence changed
/// enough to be re-fitted. A box merely next to a change (the table under a new object) is not touched and
/// keeps its id and content.
[[nodiscard]] std::vector<std::uint64_t> boxes_touched(const std::vector<Box>& previous,
                                                       const std::vector<Eigen::Vector3d>& changed_C,
                                                       double min_share = 0.0);

/// The outcome of one reconciliation.
struct Reconciled final {
  std::vector<Box> boxes;  ///< the whole new box list, sorted by id
  std::vector<Box> added;
  std::vector<Box> modified;
  std::vector<std::uint64_t> removed;
  std::uint64_t next_id = 1;  ///< the id the next new box gets; ids are never reused

  [[nodiscard]] bool changed() const { return !added.empty() || !modified.empty() || !removed.empty(); }
};

/// Merges `resegmented` (boxes fitted to the evidence of the changed area, ids ignored) into `previous`:
/// boxes not in `in_scope` are kept as they are; in-scope boxes are matched to new boxes greedily by bounds
/// IoU (best first) and keep their id (modified, or unchanged within tolerance); unmatched new boxes get
/// fresh ids from `next_id`; unmatched in-scope boxes are removed. Deterministic for the same inputs.
/// @throws Error if `next_id` is not above every id in `previous`.
[[nodiscard]] Reconciled reconcile(const std::vector<Box>& previous,
                                   const std::vector<std::uint64_t>& in_scope,
                                   const std::vector<Box>& resegmented, std::uint64_t next_id,
                                   const ReconcileParams& options = {});

}  // namespace cellmap
