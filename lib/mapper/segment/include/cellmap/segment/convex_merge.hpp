// SPDX-License-Identifier: Apache-2.0
#pragma once
// Object-level merging: join segments across convex edges, keep concave edges as splits (LCCP's criterion).

#include "cellmap/frame/cloud.hpp"
#include "cellmap/preprocess/neighbourhoods.hpp"
#include "cellmap/segment/segments.hpp"

namespace cellmap {

struct ConvexMergeParams final {
  double gap = 0.01;           ///< metres: points of two segments this close make the segments adjacent
  double patch_radius = 0.02;  ///< metres: radius of the local patches compared across a boundary
  double concavity_tolerance = 0.08;  ///< radians: a concave edge whose normals differ less counts as smooth
  int min_boundary_points = 5;        ///< adjacent segment pairs with fewer boundary points are not merged
  int samples_per_boundary = 40;      ///< boundary places evaluated per segment pair (evenly spread)
};

struct MergeStats final {
  std::size_t adjacent_pairs = 0;  ///< segment pairs that touch
  std::size_t convex_pairs = 0;    ///< of those, judged convex (merged)
};

/// Merges adjacent segments whose common boundary is convex. The criterion is LCCP's (Stein et al. 2014,
/// pcl::LCCPSegmentation::connIsConvex): for patches s, t with centroids x_s, x_t and normals n_s, n_t
/// (oriented toward the sensor), the connection is convex when angle(n_s, x_s − x_t) <= angle(n_t, x_s −
/// x_t), i.e. v = (n_s − n_t)·d̂ >= 0 with d̂ the unit vector from x_t to x_s; a concave bend by β gives v ≈ −2
/// sin(β/2), so concave bends below concavity_tolerance still count (LCCP's smooth case). Instead of
/// comparing whole supervoxels (centroids of large segments say little about their common edge) it is
/// evaluated locally: at up to samples_per_boundary evenly spread boundary point pairs (i in s, j in t,
/// closer than gap), the patches are the points of s within patch_radius of i and of t within patch_radius of
/// j, with their mean normals; the median v over these places decides. Convex pairs are merged most convex
/// first, and a merge that would join two groups with a concave boundary between them is refused, so a small
/// fragment convex to both an object and the table cannot chain them. A cube's faces thus become one
/// segment, while a box on a table or on another box stays separate. `neighbourhoods` must hold normals for
/// `cloud`. Cost: two radius searches per evaluated place. @throws Error if the sizes disagree.
[[nodiscard]] Segments merge_convex(const Cloud& cloud, const Neighbourhoods& neighbourhoods,
                                    const Segments& segments, const ConvexMergeParams& params,
                                    MergeStats* stats = nullptr);

}  // namespace cellmap
