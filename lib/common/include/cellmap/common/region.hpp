// SPDX-License-Identifier: Apache-2.0
#pragma once
// An axis-aligned region of space: the one axis-aligned box type (cell bounds, change regions, workspace
// boxes, evaluation regions).

#include <Eigen/Core>

namespace cellmap {

/// An axis-aligned region of the cell frame, metres; min <= max componentwise for a non-empty region.
struct Region final {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();

  /// Volume in m³; 0 for an empty or inverted region.
  [[nodiscard]] double volume() const { return (max - min).cwiseMax(0.0).prod(); }
  /// True when p lies inside the region grown by `tolerance` on every side (boundary included).
  [[nodiscard]] bool contains(const Eigen::Vector3d& p, double tolerance = 0.0) const {
    return (p.array() >= min.array() - tolerance).all() && (p.array() <= max.array() + tolerance).all();
  }
  /// The common part (possibly empty: check volume()).
  [[nodiscard]] Region intersection(const Region& other) const {
    return {min.cwiseMax(other.min), max.cwiseMin(other.max)};
  }
  /// This region grown by `margin` metres on every side.
  [[nodiscard]] Region grown(double margin) const { return {min.array() - margin, max.array() + margin}; }
};

}  // namespace cellmap
