// SPDX-License-Identifier: Apache-2.0
#pragma once
// Per-point k-neighbourhoods and the features the paper derives from them (eq. 1 and 2).
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <Eigen/Core>

#include <vector>

#include "cellmap/frame/cloud.hpp"

namespace cellmap {

/// The k nearest neighbours of every point of a cloud (the point itself excluded) and what the paper computes
/// from them. Indices refer to the cloud the neighbourhoods were computed on. Plain value type.
struct Neighbourhoods final {
  int k = 0;
  /// Neighbour j of point i is `indices[i * k + j]`, nearest first; -1 when the cloud has fewer than k + 1
  /// points. `sq_distances` has the same layout (squared metres).
  std::vector<int> indices;
  std::vector<float> sq_distances;
  /// Eq. 1: mean distance (metres) from each point to its k neighbours.
  std::vector<float> mean_distance;
  /// Unit surface normal from eq. 2 (the eigenvector of the smallest eigenvalue of the covariance of the
  /// point and its k neighbours), oriented toward the viewpoint. Empty unless requested.
  std::vector<Eigen::Vector3f> normals;
  /// Surface variation κ = λ1 / (λ1 + λ2 + λ3) with λ1 the smallest eigenvalue, in [0, 1/3]. Empty unless
  /// requested.
  std::vector<float> curvature;

  [[nodiscard]] int size() const { return static_cast<int>(mean_distance.size()); }
  [[nodiscard]] int neighbour(int i, int j) const { return indices[static_cast<std::size_t>(i) * k + j]; }
  [[nodiscard]] float sq_distance(int i, int j) const {
    return sq_distances[static_cast<std::size_t>(i) * k + j];
  }
};

/// Builds a kd-tree (PointSearch, as pcl::search::KdTree builds it) on `cloud` and finds each point's k
/// nearest neighbours. With `with_normals`, also the covariance (eq. 2), normals oriented toward `viewpoint`
/// (the sensor origin, same frame as the cloud) and curvature. Cost: one kd-tree build and n k-NN queries,
/// split over up to `threads` threads (the result does not depend on it).
/// @throws Error if k < 1 or the cloud has a non-finite point.
[[nodiscard]] Neighbourhoods compute_neighbourhoods(
    const Cloud& cloud, int k, bool with_normals, const Eigen::Vector3f& viewpoint = Eigen::Vector3f::Zero(),
    int threads = 1);

/// The neighbourhoods of the points `kept` (ascending indices into the cloud of `all`), renumbered to
/// 0..kept.size()-1 as in a cloud made of those points: neighbours that were not kept are removed from each
/// list (the rest stay nearest first; the list is padded with -1). Mean distances, normals and curvature are
/// copied, i.e. they still include the removed points. This lets the pipeline search the kd-tree once for
/// outlier removal and features. @throws Error if an index is out of range or not ascending.
[[nodiscard]] Neighbourhoods subset_neighbourhoods(const Neighbourhoods& all, const std::vector<int>& kept);

}  // namespace cellmap
