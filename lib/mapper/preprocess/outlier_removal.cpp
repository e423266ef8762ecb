// SPDX-License-Identifier: Apache-2.0
#include "cellmap/preprocess/outlier_removal.hpp"

#include <cmath>

#include "cellmap/common/error.hpp"

namespace cellmap {

OutlierResult remove_outliers(const Neighbourhoods& neighbourhoods, double u, OutlierMode mode) {
  if (!std::isfinite(u) || u < 0.0) throw Error("outlier removal: u must be >= 0, got " + std::to_string(u));
  const std::vector<float>& d = neighbourhoods.mean_distance;
  OutlierResult result;
  if (mode == OutlierMode::kOff || d.size() < 2) {
    result.kept.resize(d.size());
    for (std::size_t i = 0; i < d.size(); ++i) result.kept[i] = static_cast<int>(i);
    return result;
  }
  // Mean and unbiased standard deviation exactly as pcl::StatisticalOutlierRemoval (1.13) computes them: the
  // squares are formed in float, the sums in double. This keeps the one-sided mode bit-identical to PCL.
  double sum = 0.0, sq_sum = 0.0;
  for (const float& distance : d) {
    sum += distance;
    sq_sum += distance * distance;
  }
  const double n = static_cast<double>(d.size());
  result.mean = sum / n;
  const double variance = (sq_sum - sum * sum / n) / (n - 1.0);
  result.stddev = std::sqrt(std::max(variance, 0.0));
  const double upper = result.mean + u * result.stddev;
  const double lower = result.mean - u * result.stddev;
  result.kept.reserve(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (d[i] > upper) {
      ++result.removed_sparse;
    } else if (mode == OutlierMode::kTwoSided && d[i] < lower) {
      ++result.removed_dense;
    } else {
      result.kept.push_back(static_cast<int>(i));
    }
  }
  return result;
}

}  // namespace cellmap
