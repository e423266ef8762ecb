// SPDX-License-Identifier: Apache-2.0
#pragma once
// The cell pipeline's safety pass (internal): every occupied voxel of the map wholly inside a box at every
// version, including the voxels noise added outside the changed area since that area was last fitted.

#include <Eigen/Core>

#include <unordered_set>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/environment/reconcile.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/segment/fit.hpp"

namespace cellmap {

/// Whether `box` holds the whole axis-aligned cube of edge `edge` around `centre_C` (0.1 µm tolerance).
[[nodiscard]] bool holds_cube(const Box& box, const Eigen::Vector3d& centre_C, double edge);

/// Whether some box of a set holds a voxel's whole cube (holds_cube of each), answered faster than asking
/// each box in turn: each box's rotation and bounds are worked out once, and the box that held the last
/// voxel asked is asked first (voxels asked in key order mostly lie in the box of the one before). Holds
/// its own copy of what it needs; not thread-safe (one instance per thread).
class CubeHolders final {
 public:
  CubeHolders(const std::vector<Box>& boxes, double edge);
  [[nodiscard]] bool hold(const Eigen::Vector3d& centre_C);

 private:
  struct Held {
    Region bounds;
    Eigen::Matrix3d rotation;
    Eigen::Vector3d center, half_extents, cube_half;  // cube_half: the cube's, along the box's axes
  };
  [[nodiscard]] static bool holds(const Held& box, const Eigen::Vector3d& centre_C);

  std::vector<Held> boxes_;
  std::size_t last_ = 0;
};

/// The occupied voxels of a map, hashed for neighbour queries; kept up with the map sweep by sweep from the
/// flips each update reports, so that a version does not pay a pass over the whole map for them.
class OccupiedVoxels final {
 public:
  OccupiedVoxels() = default;
  /// Every occupied voxel of `map` now.
  explicit OccupiedVoxels(const OccupancyMap& map);
  /// Follows the map through one update: `update` is what OccupancyMap::integrate returned for the map
  /// these voxels are of (appeared and vanished sorted by key (z, y, x)).
  void apply(const OccupancyUpdate& update);
  /// Whether the voxel `key` is occupied and one of a 26-connected group of at least `size` occupied voxels.
  [[nodiscard]] bool in_group_of(const octomap::OcTreeKey& key, int size) const;
  /// As above, for the voxel of `map` whose centre is `centre_C`.
  [[nodiscard]] bool in_group_of(const OccupancyMap& map, const Eigen::Vector3d& centre_C, int size) const;
  /// Every occupied voxel, sorted by key (z, y, x).
  [[nodiscard]] const std::vector<octomap::OcTreeKey>& keys() const { return keys_; }

 private:
  std::vector<octomap::OcTreeKey> keys_;
  std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash> set_;
};

/// Centres of the occupied voxels that no single box of `boxes` holds whole and that belong to a
/// 26-connected group of at least `min_group` occupied voxels, sorted by key (z, y, x); the voxels split
/// over up to `threads` threads (the result does not depend on it).
[[nodiscard]] std::vector<Eigen::Vector3d> voxels_outside(const OccupancyMap& map,
                                                          const OccupiedVoxels& voxels,
                                                          const std::vector<Box>& boxes, int min_group,
                                                          int threads = 1);

/// The 26-connected groups of voxels given by their centres (on the grid of edge `voxel`), each in the
/// order its voxels were reached, the groups in the order of their first voxel.
[[nodiscard]] std::vector<std::vector<Eigen::Vector3d>> connected_groups(
    const std::vector<Eigen::Vector3d>& centres_C, double voxel);

/// How the safety pass covers what is left out.
struct CoverParams final {
  double voxel = 0.02;  ///< voxel edge, metres
  /// A box may grow by this share of its volume (as it was before the pass) to take voxels (the join rule).
  double max_growth = 0.1;
  double reach = 0.04;                ///< metres: a box takes only voxels whose cube lies this close to it
  BoxKind kind = BoxKind::kOriented;  ///< of the new boxes
};

/// Makes the boxes of `reconciled` hold every voxel of `centres_C` whole. The voxels no box holds are taken
/// in 26-connected groups: a group whose every voxel lies within `reach` of a box goes to the boxes, each
/// voxel to the box that grows least to take it, no box growing by more than `max_growth` of its volume in
/// the pass (a box grown is then modified, or stays added if it is new); any other group (an object, or the
/// part of one its change has not reported yet) gets a new box with a fresh id from `reconciled.next_id`,
/// rather than hide in an older box. Keeps `reconciled`'s lists sorted by id.
void cover(Reconciled& reconciled, const std::vector<Eigen::Vector3d>& centres_C, const CoverParams& options);

}  // namespace cellmap
