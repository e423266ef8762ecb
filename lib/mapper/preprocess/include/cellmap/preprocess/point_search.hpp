// SPDX-License-Identifier: Apache-2.0
#pragma once
// Exact nearest-neighbour and radius queries on a cloud's points, for the stages that search a cloud point
// by point (neighbourhoods, region growing's leftovers, convex merging's patches, supervoxel filling).

#include <pcl/types.h>

#include <memory>
#include <vector>

#include "cellmap/frame/cloud.hpp"

namespace cellmap {

/// A kd-tree over a cloud's points (or some of them), built as pcl::search::KdTree builds it (FLANN's
/// single kd-tree, at most 15 points a leaf, exact search), so every query finds what PCL's would, ties in
/// the same order. Queried here without PCL's wrapper: FLANN opens an OpenMP region for every single query
/// through it, a futex round trip that was 40 % of the time of a 900-point segmentation.
///
/// The points are copied: the cloud need not outlive the search. Every point searched must be finite
/// (throws cellmap::Error). Queries are const and safe to run concurrently.
class PointSearch {
 public:
  /// Indexes every point of `cloud`.
  explicit PointSearch(const Cloud& cloud);
  /// Indexes the points `cloud[subset[i]]`; results are indices into `cloud`.
  PointSearch(const Cloud& cloud, const std::vector<int>& subset);
  ~PointSearch();
  PointSearch(PointSearch&&) noexcept;
  PointSearch& operator=(PointSearch&&) noexcept;

  /// The k indexed points nearest `query` (k clamped to how many there are), nearest first, with their
  /// squared distances (m²). Returns how many were found.
  int nearest(const pcl::PointXYZ& query, int k, pcl::Indices& indices,
              std::vector<float>& sq_distances) const;
  /// The indexed points closer than `radius` (metres) to `query`, nearest first if `sorted` (otherwise in
  /// the tree's order). Returns how many were found.
  int within(const pcl::PointXYZ& query, double radius, bool sorted, pcl::Indices& indices,
             std::vector<float>& sq_distances) const;
  /// How many points are indexed.
  [[nodiscard]] int size() const;

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

}  // namespace cellmap
