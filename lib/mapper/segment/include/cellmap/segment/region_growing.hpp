// SPDX-License-Identifier: Apache-2.0
#pragma once
// Region growing segmentation (paper Alg. 1) and the coverage of the points it leaves over.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include "cellmap/frame/cloud.hpp"
#include "cellmap/preprocess/neighbourhoods.hpp"
#include "cellmap/segment/segments.hpp"

namespace cellmap {

/// The paper's three region conditions.
struct RegionGrowingParams final {
  double gap = 0.01;  ///< d_th (eq. 3), metres: a neighbour farther than this never joins the region
  double max_curvature = 0.03;  ///< κ_th (eq. 4): only points with κ <= κ_th continue the growth (seeds)
  double max_angle = 0.07;      ///< α_th (eq. 5), radians (4°): max angle between the normals of neighbours
  int min_cluster_size = 50;    ///< regions with fewer points are dissolved (their points become leftovers)
};

/// Alg. 1 on precomputed neighbourhoods (with normals): seeds in ascending curvature; a region takes each
/// k-neighbour j of a member i with |p_i − p_j| <= gap and angle(n_i, n_j) <= max_angle, and grows on from j
/// only when κ_j <= max_curvature. Written on our kd-tree neighbour lists rather than pcl::RegionGrowing
/// because PCL's has no distance cap and recomputes its neighbour lists (see bench/segment_bench.cpp for the
/// measured comparison). Cost: O(n·k). @throws Error if the neighbourhoods have no normals or a parameter is
/// invalid.
[[nodiscard]] Segments grow_regions(const Neighbourhoods& neighbourhoods, const RegionGrowingParams& params);

/// What happened to the points that region growing left in no segment.
struct LeftoverStats final {
  std::size_t attached = 0;         ///< joined the segment of their nearest segmented point within `gap`
  std::size_t own_segments = 0;     ///< new segments made of leftover groups (Euclidean clusters at `gap`)
  std::size_t in_own_segments = 0;  ///< points in those segments
  std::size_t isolated = 0;         ///< dropped: in a leftover group of fewer than `min_points` points
};

/// Gives every unlabelled point a segment, so that no obstacle point is silently lost: first, in waves, each
/// joins the segment of its nearest labelled k-neighbour within `gap` metres (a band of leftovers between two
/// segments is shared out by distance, never turned into a bridge between them); the rest, which reach no
/// segment, are grouped by Euclidean clustering at `gap`, and each group of at least `min_points` points
/// becomes its own segment. Smaller groups (isolated points that survived outlier removal: fewer than
/// `min_points` points within reach) are the one documented drop; `stats.isolated` counts them. Mutates
/// `segments`.
/// @throws Error if the sizes disagree or gap <= 0.
LeftoverStats cover_leftovers(const Cloud& cloud, const Neighbourhoods& neighbourhoods, Segments& segments,
                              double gap, int min_points);

}  // namespace cellmap
