// SPDX-License-Identifier: Apache-2.0
#pragma once
// Unknown space: the voxels of the workspace that no sensor has observed (never hit, never crossed by a ray;
// the robot's body, which the self filter cuts out, included), covered by few conservative axis-aligned
// boxes, so that a planner does not take space nobody looked at for free space.

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/common/region.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"

namespace cellmap {

/// How unknown space is covered with boxes.
struct UnknownConfig final {
  /// Edge of the smallest cube an unknown pocket must hold to be covered, metres (default 0.10: what a
  /// person's limb could not hide in). Pockets no such cube fits in are ignored: the gaps between diverging
  /// rays far from a sensor, thin shells just behind a seen surface. Rounded up to whole voxels.
  double min_size = 0.10;
  /// The most seen free space a box may take in each time it grows by one voxel layer, as a share of that
  /// layer, [0, 0.5] (default 0.2). Occupied voxels and ignored unknown voxels cost nothing: covering them
  /// blocks nothing a planner could use.
  double max_free_share = 0.2;
  /// Boxes are joined, cheapest join first (the least seen free space added), until at most this many
  /// remain, [1, 10000] (default 20); joins whose added space (the joined box less the two) is at most
  /// `max_free_share` seen free space are made whatever the count.
  int max_boxes = 20;

  /// @throws Error naming the field if a value is out of range or not finite.
  void validate() const;
};

/// The occupancy states of a box-shaped block of voxels, one byte each, aligned to a map's voxels (or
/// written directly, for synthetic scenes). Voxel (x, y, z) spans [origin + (x, y, z)·resolution,
/// origin + (x + 1, y + 1, z + 1)·resolution) in the cell frame C. Plain value type.
class VoxelStateGrid final {
 public:
  /// A grid of `size` voxels of edge `resolution` metres whose voxel (0, 0, 0) has its low corner at
  /// `origin_C`, every voxel unknown. @throws Error if a size is < 1, the grid exceeds 2^27 voxels or
  /// resolution <= 0.
  VoxelStateGrid(const Eigen::Vector3i& size, double resolution, const Eigen::Vector3d& origin_C);

  /// The voxels of `map` whose centres lie in `workspace` (every voxel the region touches, aligned to the
  /// map's keys), with their states: coarse leaves of the map (pruned free or occupied space) set every
  /// voxel they span. Cost: one pass over the map's leaves in the region. @throws Error if the workspace is
  /// empty or not finite, or spans more than 2^27 voxels.
  [[nodiscard]] static VoxelStateGrid of(const OccupancyMap& map, const Region& workspace);

  [[nodiscard]] const Eigen::Vector3i& size() const { return size_; }
  [[nodiscard]] double resolution() const { return resolution_; }
  [[nodiscard]] const Eigen::Vector3d& origin() const { return origin_; }
  [[nodiscard]] std::size_t voxel_count() const { return states_.size(); }
  /// The state of voxel (x, y, z), which must lie in the grid.
  [[nodiscard]] VoxelState at(int x, int y, int z) const { return states_[index(x, y, z)]; }
  void set(int x, int y, int z, VoxelState state) { states_[index(x, y, z)] = state; }
  /// Sets every voxel of [low, high) (voxel indices, clipped to the grid) to `state`.
  void fill(const Eigen::Vector3i& low, const Eigen::Vector3i& high, VoxelState state);

 private:
  [[nodiscard]] std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * size_.y() + y) * size_.x() + x;
  }

  Eigen::Vector3i size_;
  double resolution_;
  Eigen::Vector3d origin_;
  std::vector<VoxelState> states_;
};

/// Unknown space covered with boxes, and what the cover costs, all in m³.
struct UnknownCover final {
  /// Axis-aligned unknown boxes (space unknown, rotation identity, id 0: the caller numbers them) in the cell
  /// frame, each spanning whole voxels; `points` is the number of unknown voxels it holds (ignored ones
  /// included). Every unknown voxel that is not ignored lies in at least one box. Sorted by (min z, min y,
  /// min x) corner.
  std::vector<Box> boxes;
  double grid_volume = 0.0;          ///< the whole grid (the workspace, to whole voxels)
  double unknown_volume = 0.0;       ///< never observed
  double ignored_volume = 0.0;       ///< never observed but in pockets smaller than min_size: in no box
  double blocked_free_volume = 0.0;  ///< observed free yet inside some box (each voxel counted once)
  double boxed_volume = 0.0;         ///< inside some box (each voxel counted once)
};

/// Covers the unknown voxels of `grid` with boxes (see UnknownConfig): the pockets a cube of min_size fits
/// in, grown box by box from their lowest voxel layer by layer while a layer adds no more than
/// max_free_share of seen free space, then joined down to max_boxes. Deterministic. Cost: linear in the
/// grid's voxels for the pockets, plus the boxes' growth (a few layers' sums each) and the joins (quadratic
/// in the boxes grown). @throws Error if `config` is invalid.
[[nodiscard]] UnknownCover cover_unknown(const VoxelStateGrid& grid, const UnknownConfig& config = {});

/// Whether the voxels of `grid` whose centres no box of `boxes` holds include a whole cube of edge `edge_m`
/// metres (rounded up to whole voxels, as UnknownConfig::min_size): whether covering the grid with `boxes`
/// instead of with one box over all of it frees space a limb could be in. Cost: linear in the grid's voxels
/// times the boxes.
[[nodiscard]] bool frees_a_cube(const VoxelStateGrid& grid, const std::vector<Box>& boxes, double edge_m);

}  // namespace cellmap
