// SPDX-License-Identifier: Apache-2.0
#pragma once
// The paper's path representation: a clamped uniform cubic B-spline z(d, t) over control points d.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <Eigen/Core>

#include <vector>

namespace cellmap::planning {

/// A clamped uniform B-spline of degree min(3, m − 1) through m control points d_0 … d_{m−1} of equal
/// dimension (joint vectors q, or for the gantry the tool position, which is the same up to a constant
/// offset). Clamped: the path starts at d_0 and ends at d_{m−1}; interior knots are uniform on t ∈ [0, 1].
/// Each point is a convex combination of at most 4 neighbouring control points. Immutable value; thread-safe.
class BSplinePath final {
 public:
  /// @throws Error if fewer than 2 control points, their sizes differ or are 0, or a value is not finite.
  explicit BSplinePath(std::vector<Eigen::VectorXd> control_points);

  /// z(t), t clamped to [0, 1]. Costs O(degree²) (de Boor).
  [[nodiscard]] Eigen::VectorXd at(double t) const;
  /// The N checkpoints t_k = k / (N − 1), k = 0 … N − 1 (N = 1: t = 0). @throws Error if n < 1.
  [[nodiscard]] std::vector<Eigen::VectorXd> sample(int n) const;

  [[nodiscard]] int degree() const { return degree_; }
  [[nodiscard]] const std::vector<Eigen::VectorXd>& control_points() const { return points_; }

 private:
  std::vector<Eigen::VectorXd> points_;
  std::vector<double> knots_;
  int degree_ = 3;
};

}  // namespace cellmap::planning
