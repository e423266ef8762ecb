// SPDX-License-Identifier: Apache-2.0
#pragma once
// Path checks for planners: a B-spline path sampled at N checkpoints, every robot box against every
// environment box.

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cellmap/collision/batch.hpp"
#include "cellmap/collision/box_tree.hpp"
#include "cellmap/collision/robot_boxes.hpp"
#include "cellmap/planning/bspline.hpp"

namespace cellmap::planning {

/// The robot's boxes in the cell frame at each of the n checkpoints of `path` (whose points are joint vectors
/// of robot.robot()). @throws Error if n < 1 or the path's dimension is not the robot's dof.
[[nodiscard]] std::vector<std::vector<collision::Obb>> place_along(const collision::RobotBoxes& robot,
                                                                   const BSplinePath& path, int n);

/// The constraint vector of the path: n_constr = n_rob · n_env · N entries with distance, witness points and
/// normal (see collision::constraints). @throws Error as place_along.
[[nodiscard]] collision::ConstraintSet path_constraints(const collision::RobotBoxes& robot,
                                                        const BSplinePath& path, int n_checkpoints,
                                                        const std::vector<collision::Obb>& environment);

/// How a path check treats the environment's boxes.
struct PathCheckOptions final {
  /// Take unknown boxes (space no sensor has observed) for free space. Off by default: an unobserved region
  /// may hold anything, so a path through it is blocked (docs/environment.md#unknown-space). A planner that
  /// accepts that risk, e.g. for a slow first move that lets the sensors look, sets it.
  bool ignore_unknown = false;
};

/// The boxes of one environment version that paths are checked against, as the collision library takes
/// them: the boxes as Obb with their AABB tree, and the id and space of the cellmap::Box each came from.
/// With options.ignore_unknown the unknown boxes are left out here, so obbs() and tree() also give
/// collision::constraints and path_constraints the boxes a path must keep clear of. Built once per version
/// (O(n log n)) and shared by every path checked against it; immutable, safe to read from many threads.
class PathEnvironment final {
 public:
  /// Takes `boxes` in the cell frame (e.g. Environment::boxes()).
  explicit PathEnvironment(const std::vector<Box>& boxes, PathCheckOptions options = {});

  /// The boxes kept, in the order of the input.
  [[nodiscard]] const std::vector<collision::Obb>& obbs() const { return obbs_; }
  [[nodiscard]] const collision::BoxTree& tree() const { return tree_; }
  /// Id and space of the Box that obbs()[index] came from.
  [[nodiscard]] std::uint64_t id(int index) const { return ids_.at(static_cast<std::size_t>(index)); }
  [[nodiscard]] BoxSpace space(int index) const { return spaces_.at(static_cast<std::size_t>(index)); }
  /// Unknown boxes left out (ignore_unknown).
  [[nodiscard]] std::size_t ignored() const { return ignored_; }

 private:
  // Fills every member but tree_ from `boxes` and returns obbs_, for tree_'s initialiser.
  const std::vector<collision::Obb>& keep(const std::vector<Box>& boxes, PathCheckOptions options);

  std::vector<collision::Obb> obbs_;
  std::vector<std::uint64_t> ids_;
  std::vector<BoxSpace> spaces_;
  std::size_t ignored_ = 0;
  collision::BoxTree tree_;  // declared after obbs_: built from it
};

/// Where a path first violates the safety margin δ, if it does.
struct Blocking final {
  bool blocked = false;
  int checkpoint = -1;
  int robot_box = -1;
  int env_box = -1;       ///< index of the blocking box in the environment checked against
  double distance = 0.0;  ///< signed distance of that pair (< margin)
  double t = 0.0;         ///< path parameter of the checkpoint, [0, 1] (BSplinePath::sample)
  /// Id of the blocking box; 0 when checked against bare Obbs, which carry none.
  std::uint64_t box_id = 0;
  /// Whether an obstacle or an unknown box blocks; checked against bare Obbs every box counts as occupied.
  BoxSpace space = BoxSpace::kOccupied;
  /// Cell frame: the blocking box's witness point (SignedDistance::point_b), where the robot box comes
  /// closest to it or, overlapping, meets it along the shortest separation: where the path runs into the box.
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

/// "Is the path blocked?": walks checkpoints in order and stops at the first pair closer than `margin` (>=
/// 0). The broad phase (`environment.tree()`) skips far boxes; the separating-axis test rejects most of the
/// rest before an exact distance is computed. Unknown boxes block as obstacles do unless the environment was
/// made with ignore_unknown; the result names the box's id and space. @throws Error as place_along, or if
/// margin < 0.
[[nodiscard]] Blocking path_blocked(const collision::RobotBoxes& robot, const BSplinePath& path,
                                    int n_checkpoints, const PathEnvironment& environment, double margin);

/// As above against bare boxes (`tree` built over `environment`), all taken as obstacles: box_id stays 0 and
/// env_box is the index into `environment`.
[[nodiscard]] Blocking path_blocked(const collision::RobotBoxes& robot, const BSplinePath& path,
                                    int n_checkpoints, const std::vector<collision::Obb>& environment,
                                    const collision::BoxTree& tree, double margin);

}  // namespace cellmap::planning
