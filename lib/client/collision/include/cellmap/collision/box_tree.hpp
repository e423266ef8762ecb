// SPDX-License-Identifier: Apache-2.0
#pragma once
// Broad phase: a static AABB tree over environment boxes, so a query touches only the boxes near it.

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "cellmap/collision/obb.hpp"

namespace cellmap::collision {

/// A bounding-volume hierarchy of the axis-aligned bounds of a fixed set of boxes (median split on the widest
/// axis, leaves of up to 4 boxes). Built once per environment version (O(n log n)); queries are read-only and
/// may run concurrently.
class BoxTree final {
 public:
  /// Builds the tree over `boxes` (indices refer to this vector; the tree keeps no reference to it).
  explicit BoxTree(const std::vector<Obb>& boxes);

  /// Appends to `out` the indices of the boxes whose bounds touch or lie closer than `cutoff` (>= 0, metres)
  /// to the axis-aligned box (center, half_extents). The AABB gap is a lower bound of the true distance, so a
  /// box not returned is at least `cutoff` away. Order unspecified.
  void query(const Eigen::Vector3d& center, const Eigen::Vector3d& half_extents, double cutoff,
             std::vector<int>* out) const;

  [[nodiscard]] std::size_t size() const { return count_; }

 private:
  struct Node {
    Eigen::Vector3d lo, hi;
    int first = 0;  // leaf: start of its range in order_; inner: left child
    int right = 0;  // inner: right child
    int count = 0;  // > 0 for leaves
  };
  int build(int begin, int end, const std::vector<Eigen::Vector3d>& lo,
            const std::vector<Eigen::Vector3d>& hi);

  std::vector<Node> nodes_;
  std::vector<int> order_;
  std::vector<Eigen::Vector3d> lo_, hi_;
  std::size_t count_ = 0;
};

}  // namespace cellmap::collision
