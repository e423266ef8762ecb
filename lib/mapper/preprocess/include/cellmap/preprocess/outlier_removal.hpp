// SPDX-License-Identifier: Apache-2.0
#pragma once
// Statistical outlier removal on the mean neighbour distance (paper eq. 1).
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <vector>

#include "cellmap/preprocess/neighbourhoods.hpp"

namespace cellmap {

/// How the threshold is applied to the mean distances d_i (mean μ, sample standard deviation σ over all
/// points).
enum class OutlierMode {
  /// The paper: keep μ − u·σ ≤ d_i ≤ μ + u·σ. Also drops points that are unusually *dense* (d_i small), e.g.
  /// duplicated returns or points much closer to the sensor than the rest.
  kTwoSided,
  /// pcl::StatisticalOutlierRemoval: keep d_i ≤ μ + u·σ; only sparse points are outliers. Same arithmetic as
  /// PCL 1.13 (float distances, unbiased σ), so it keeps exactly the points PCL's filter keeps.
  kOneSided,
  /// Keep every point.
  kOff,
};

/// Which points survive, as indices into the cloud the neighbourhoods belong to (ascending).
struct OutlierResult final {
  std::vector<int> kept;
  std::size_t removed_sparse = 0;  ///< d_i > μ + u·σ
  std::size_t removed_dense = 0;   ///< d_i < μ − u·σ (two-sided mode only)
  double mean = 0.0;               ///< μ (metres)
  double stddev = 0.0;             ///< σ (metres)
};

/// Applies the statistical outlier test with multiplier `u` (σ units) to `neighbourhoods.mean_distance`.
/// @throws Error if u is negative or not finite.
[[nodiscard]] OutlierResult remove_outliers(const Neighbourhoods& neighbourhoods, double u, OutlierMode mode);

}  // namespace cellmap
