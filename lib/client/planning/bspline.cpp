// SPDX-License-Identifier: Apache-2.0
#include "cellmap/planning/bspline.hpp"

#include <algorithm>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap::planning {

BSplinePath::BSplinePath(std::vector<Eigen::VectorXd> control_points) : points_(std::move(control_points)) {
  if (points_.size() < 2)
    throw Error("B-spline: needs at least 2 control points, got " + std::to_string(points_.size()));
  const Eigen::Index dim = points_.front().size();
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const std::string where = "B-spline: control point " + std::to_string(i);
    if (points_[i].size() == 0 || points_[i].size() != dim) {
      throw Error(where + ": has " + std::to_string(points_[i].size()) + " coordinates, expected " +
                  std::to_string(dim) + " (> 0)");
    }
    if (!points_[i].allFinite()) throw Error(where + ": not finite");
  }
  const int m = static_cast<int>(points_.size());
  degree_ = std::min(3, m - 1);
  // Clamped: degree + 1 repeated knots at each end, m − degree − 1 uniform interior knots.
  const int spans = m - degree_;
  for (int i = 0; i <= degree_; ++i) knots_.push_back(0.0);
  for (int i = 1; i < spans; ++i) knots_.push_back(static_cast<double>(i) / spans);
  for (int i = 0; i <= degree_; ++i) knots_.push_back(1.0);
}

Eigen::VectorXd BSplinePath::at(double t) const {
  t = std::clamp(t, 0.0, 1.0);
  const int m = static_cast<int>(points_.size());
  const int p = degree_;
  // Knot span s with knots_[s] <= t < knots_[s + 1]; t = 1 uses the last non-empty span.
  int s = p;
  while (s < m - 1 && t >= knots_[s + 1]) ++s;
  // de Boor's recursion on the p + 1 affected control points.
  std::vector<Eigen::VectorXd> d(points_.begin() + (s - p), points_.begin() + (s + 1));
  for (int r = 1; r <= p; ++r) {
    for (int j = p; j >= r; --j) {
      const int i = j + s - p;
      const double denominator = knots_[i + p - r + 1] - knots_[i];
      const double alpha = denominator > 0.0 ? (t - knots_[i]) / denominator : 0.0;
      d[j] = (1.0 - alpha) * d[j - 1] + alpha * d[j];
    }
  }
  return d[p];
}

std::vector<Eigen::VectorXd> BSplinePath::sample(int n) const {
  if (n < 1) throw Error("B-spline: checkpoint count must be >= 1, got " + std::to_string(n));
  std::vector<Eigen::VectorXd> out;
  out.reserve(n);
  for (int k = 0; k < n; ++k) out.push_back(at(n == 1 ? 0.0 : static_cast<double>(k) / (n - 1)));
  return out;
}

}  // namespace cellmap::planning
