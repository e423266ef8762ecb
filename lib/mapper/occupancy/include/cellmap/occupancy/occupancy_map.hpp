// SPDX-License-Identifier: Apache-2.0
#pragma once
// The occupancy map: an octomap::OcTree that each sweep updates with hits at the points and free-space
// evidence along the rays from each scan's origin.

#include <octomap/OcTree.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <vector>

#include "cellmap/common/region.hpp"
#include "cellmap/occupancy/occupancy_config.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap {

/// What one sweep did to the map. Keys are leaf keys of `OccupancyMap::tree()`, sorted by (z, y, x).
struct OccupancyUpdate final {
  std::size_t hit_voxels = 0;                ///< voxels that received a hit
  std::size_t free_voxels = 0;               ///< voxels that received free-space evidence
  std::size_t newly_observed = 0;            ///< voxels that were unknown before (never hit nor crossed)
  std::vector<octomap::OcTreeKey> appeared;  ///< voxels occupied now that were free or unknown before
  std::vector<octomap::OcTreeKey> vanished;  ///< voxels free now that were occupied before
};

class KeyUpdateUnion;
struct KeyUpdate;

/// The voxels one sweep observes, gathered scan by scan while its frames arrive, so that fusing a sweep is
/// spread over the time it takes and its end leaves only the map update (OccupancyMap::integrate). The
/// scans added one by one make exactly the map integrate(Sweep) makes of them all. Independent of any map:
/// only the config's resolution (the key layout), max_range and threads are used. Movable, not copyable;
/// not thread-safe (one instance per thread).
class ObservedVoxels final {
 public:
  /// @throws Error if `config` is invalid (see OccupancyConfig::validate).
  explicit ObservedVoxels(const OccupancyConfig& config = {});
  ~ObservedVoxels();
  ObservedVoxels(ObservedVoxels&&) noexcept;
  ObservedVoxels& operator=(ObservedVoxels&&) noexcept;
  ObservedVoxels(const ObservedVoxels&) = delete;
  ObservedVoxels& operator=(const ObservedVoxels&) = delete;

  /// Adds the voxels `scan` observes: the occupied ones at its points, the free ones along its rays and
  /// clear-only rays (the rules of OccupancyMap::integrate). Costs what fusing the scan costs, on `threads`
  /// threads (0: config.threads; a caller that adds scans to several instances side by side gives each one);
  /// the scan is consumed (pass it moved: its points are not copied). @throws Error if the scan's origin is
  /// not finite or outside the key range (nothing of it is added).
  void add(Scan scan, int threads = 0);
  /// Adds what `other` gathered (other scans of the same sweep, e.g. on another thread) and empties it.
  /// @throws Error if `other` was made at another resolution or range (nothing is added then).
  void merge(ObservedVoxels& other);
  /// Scans added since construction or the last OccupancyMap::integrate of these voxels.
  [[nodiscard]] std::size_t scans() const { return scans_; }
  /// Voxels gathered so far, as bricks of 16³ voxels (1 KB each): the memory they hold.
  [[nodiscard]] std::size_t bricks() const;

 private:
  friend class OccupancyMap;
  OccupancyConfig config_;
  std::unique_ptr<octomap::OcTree> grid_;  // the key layout; never holds a node
  std::unique_ptr<KeyUpdateUnion> union_;
  std::size_t scans_ = 0;
};

/// Occupancy of one voxel. Unknown = never observed.
enum class VoxelState { unknown, free, occupied };

/// The fused occupancy of the cell (frame C) at `OccupancyConfig::resolution`. Each sweep updates every voxel
/// it observes exactly once: +log-odds(hit) where it holds a point, +log-odds(miss) where a ray from a scan
/// origin crosses it (never both; occupied wins), so a removed object that the sensor now sees through
/// becomes free after `config().sweeps_to_clear()` sweeps. Not copyable (a map can hold millions of nodes);
/// movable. Not thread-safe: one writer, and no readers during `integrate`.
class OccupancyMap final {
 public:
  /// @throws Error if `config` is invalid (see OccupancyConfig::validate).
  explicit OccupancyMap(const OccupancyConfig& config = {});
  OccupancyMap(const OccupancyMap&) = delete;
  OccupancyMap& operator=(const OccupancyMap&) = delete;
  OccupancyMap(OccupancyMap&&) = default;
  OccupancyMap& operator=(OccupancyMap&&) = default;

  /// Fuses one sweep: computes its occupied and free voxels (compute_key_update, on config().threads
  /// threads), applies them with lazy inner-node updates and refreshes the inner nodes once. Cost is
  /// dominated by the number of distinct voxels observed, not by the number of points. Non-finite points are
  /// skipped. Clear-only rays (Scan::clear_C) add free-space evidence only, up to their ends.
  /// @return the voxels whose occupied/free state flipped, for change detection.
  /// @throws Error if a scan origin is not finite or outside the map's key range.
  OccupancyUpdate integrate(const Sweep& sweep);
  /// Fuses the sweep whose scans `voxels` gathered (the same map as integrate(Sweep) of those scans) and
  /// empties `voxels` for the next sweep. The config's resolution must equal the one `voxels` was made with.
  /// @throws Error if it does not (nothing is fused then).
  OccupancyUpdate integrate(ObservedVoxels& voxels);

  /// Takes one cloud (metres, cell frame) as settled evidence: every voxel holding one of its points is set
  /// to the upper clamp (occupied), nothing is cleared. What a batch cloud gives the map when there are no
  /// sweeps to fuse: a cloud the caller already trusts (one merged sweep, a scan from a file). Non-finite
  /// points are skipped. @return the number of points outside the map's key range (also skipped).
  std::size_t mark_occupied(const std::vector<Eigen::Vector3d>& points_C);

  /// State of the voxel holding `p_C` (metres, cell frame); unknown outside the key range.
  [[nodiscard]] VoxelState state(const Eigen::Vector3d& p_C) const;
  /// State of the leaf voxel `key`.
  [[nodiscard]] VoxelState state(const octomap::OcTreeKey& key) const;
  /// Centre of the leaf voxel `key`, metres, cell frame.
  [[nodiscard]] Eigen::Vector3d centre(const octomap::OcTreeKey& key) const;
  /// Leaf keys of all occupied voxels, sorted by (z, y, x).
  [[nodiscard]] std::vector<octomap::OcTreeKey> occupied_keys() const;
  /// Centres (metres, cell frame) of the occupied voxels whose centre lies in the box [min_C, max_C], sorted
  /// by key (z, y, x) — the occupied evidence inside a change region. Cost: the tree's leaves overlapping the
  /// box.
  [[nodiscard]] std::vector<Eigen::Vector3d> occupied_centres_in(const Eigen::Vector3d& min_C,
                                                                 const Eigen::Vector3d& max_C) const;

  /// Centres of the occupied leaf voxels inside any of `regions` (metres, cell frame), each voxel once, in
  /// (z, y, x) key order. Cost: a bounding-box walk of the tree per region.
  [[nodiscard]] std::vector<Eigen::Vector3d> occupied_centres(const std::vector<Region>& regions) const;
  /// Whether some occupied leaf voxel whose centre lies in `region` (metres, cell frame) satisfies
  /// `accept(key, centre_C)`; stops at the first that does. Cost: the tree's leaves overlapping the region
  /// up to that voxel (all of them when none does).
  [[nodiscard]] bool any_occupied_in(
      const Region& region,
      const std::function<bool(const octomap::OcTreeKey& key, const Eigen::Vector3d& centre_C)>& accept)
      const;

  /// Writes the whole map, log-odds included, to `out` (a resolution line, then OctoMap's node data), so a
  /// restarted daemon continues with the same evidence. Silent (OctoMap's .bt writer prints to stderr).
  /// @throws Error if the stream fails.
  void write(std::ostream& out) const;
  /// Replaces the map with one written by write() at the same resolution.
  /// @throws Error if the stream is not such a map (also: cut short, a node deeper than the tree, a log-odds
  /// that is not finite), its resolution differs from the config's, or it holds more than
  /// kMaxSavedOccupiedVoxels occupied voxels; the map is then left as it was.
  void read(std::istream& in);
  /// The most occupied voxels a saved map may hold: 2²² ≈ 4.2 million, at 5 cm 10 000 m² of surface one
  /// voxel thick, far beyond what a cell's sensors see. Whoever reads a map lists its occupied voxels one by
  /// one (occupied_keys), and one coarse node of a few bytes in a file can stand for 8¹⁵ of them: a state
  /// that unpacks to more is refused rather than allowed to exhaust memory.
  static constexpr std::uint64_t kMaxSavedOccupiedVoxels = std::uint64_t{1} << 22;

  /// The OcTree itself (for queries, writing .bt files, or comparison); its parameters are the config's.
  [[nodiscard]] const octomap::OcTree& tree() const { return *tree_; }
  [[nodiscard]] const OccupancyConfig& config() const { return config_; }

 private:
  OccupancyUpdate apply(const KeyUpdate& keys);

  OccupancyConfig config_;
  std::unique_ptr<octomap::OcTree> tree_;
};

/// Applies `config`'s sensor model (hit, miss, clamps, threshold) to `tree` — also for reference trees fed
/// with OcTree::insertPointCloud, so that both use the same parameters.
void apply_sensor_model(const OccupancyConfig& config, octomap::OcTree& tree);

}  // namespace cellmap
