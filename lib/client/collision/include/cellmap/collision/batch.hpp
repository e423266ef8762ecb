// SPDX-License-Identifier: Apache-2.0
#pragma once
// Batch distance queries: robot boxes × environment boxes × checkpoints → the constraint vector of the paper.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <Eigen/Core>

#include <cstddef>
#include <limits>
#include <vector>

#include "cellmap/collision/box_distance.hpp"
#include "cellmap/collision/box_tree.hpp"
#include "cellmap/collision/obb.hpp"

namespace cellmap::collision {

/// One constraint: robot box `robot_box` at checkpoint `checkpoint` against environment box `env_box`.
/// distance, points and normal as SignedDistance (A = robot box, B = environment box), cell frame.
struct Constraint final {
  int checkpoint = 0;
  int robot_box = 0;
  int env_box = 0;
  SignedDistance result;
};

/// The constraint vector of a path: the paper counts n_constr = n_rob · n_env · N. `entries` holds all of
/// them (dense, ordered by checkpoint, robot box, environment box) unless a cutoff was used; then only the
/// pairs whose bounds come closer than the cutoff are listed, the others being at least `cutoff` away.
struct ConstraintSet final {
  int n_rob = 0;
  int n_env = 0;
  int n_checkpoints = 0;
  double cutoff = std::numeric_limits<double>::infinity();
  std::vector<Constraint> entries;

  [[nodiscard]] std::size_t n_constr() const {
    return static_cast<std::size_t>(n_rob) * static_cast<std::size_t>(n_env) * n_checkpoints;
  }
  /// Smallest signed distance among the entries (+infinity if none).
  [[nodiscard]] double min_distance() const;
  /// True when every entry keeps the safety margin δ (distance >= margin) and margin < cutoff, so skipped
  /// pairs keep it too.
  [[nodiscard]] bool clear(double margin) const;
};

/// Computes the constraints for `robot_at_checkpoints[k]` (the robot's boxes at checkpoint k, all of equal
/// count) against `environment`. Dense: every pair. Thread-safe (pure).
[[nodiscard]] ConstraintSet constraints(const std::vector<std::vector<Obb>>& robot_at_checkpoints,
                                        const std::vector<Obb>& environment);

/// Where constraints_into() writes: `distance` n_constr values, point_a, point_b and normal 3 · n_constr each
/// (x, y, z per entry), all in constraints()'s order (checkpoint, robot box, environment box); a null array
/// is skipped. The caller owns them.
struct ConstraintArrays final {
  double* distance = nullptr;
  double* point_a = nullptr;
  double* point_b = nullptr;
  double* normal = nullptr;
};
/// The dense constraints written into arrays instead of a ConstraintSet (for array consumers such as the
/// Python module: no entry list is built). Values equal constraints()'s bit for bit. Thread-safe (pure).
/// @throws Error as constraints().
void constraints_into(const std::vector<std::vector<Obb>>& robot_at_checkpoints,
                      const std::vector<Obb>& environment, const ConstraintArrays& out);

/// As above with a broad phase: `tree` must be built over `environment`; only pairs whose bounds come closer
/// than `cutoff` (> 0, metres, e.g. the safety margin plus the planner's influence distance) are computed.
[[nodiscard]] ConstraintSet constraints(const std::vector<std::vector<Obb>>& robot_at_checkpoints,
                                        const std::vector<Obb>& environment, const BoxTree& tree,
                                        double cutoff);

}  // namespace cellmap::collision
