// SPDX-License-Identifier: Apache-2.0
#pragma once
// Change detection: which parts of the occupancy map changed, as connected regions with bounds, with
// hysteresis so that sensor noise does not produce changes.

#include <octomap/OcTree.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "cellmap/common/region.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"

namespace cellmap {

/// Parameters of change detection (YAML section `change`).
struct ChangeConfig final {
  /// Sweeps a voxel's new occupied/free state must hold, counting the sweep it flipped in, before the flip
  /// counts (`change.persist_sweeps`, ≥ 1; default 3). A voxel that flips back earlier never counts.
  int persist_sweeps = 3;
  /// Metres added on every side of a region's bounds (`change.margin`, ≥ 0; default 0.05).
  double margin = 0.05;
  /// A region is reported only when at least this many of its appeared voxels, or of its vanished ones, lie
  /// off the unchanged surface, i.e. have no unchanged occupied 26-neighbour (`change.min_voxels`, ≥ 1;
  /// default 2 here, 3 in cellmapd's config). Depth noise mostly moves a surface by a voxel, so its flips
  /// touch the surface they belong to and do not make a region.
  int min_voxels = 2;

  /// @throws Error naming the field if a value is out of range.
  void validate() const;
  /// Reads the `change` section (keys persist_sweeps, margin, min_voxels; absent keys keep their defaults).
  /// Keys the caller read from `section` before (the cell pipeline's settle_sweeps and gather_sweeps) are not
  /// unknown.
  /// @throws Error naming the key ("change.margin: ...") for unknown keys, wrong types or bad ranges.
  [[nodiscard]] static ChangeConfig from_yaml(YamlMap section);
};

/// One connected group (26-connectivity) of voxels whose change was confirmed in the same sweep.
struct ChangeRegion final {
  Region bounds;  ///< the changed voxels' extent grown by the margin on every side, metres, cell frame
  /// Voxels (leaf keys of the map's tree) now occupied that were free or unknown, sorted (z, y, x).
  std::vector<octomap::OcTreeKey> appeared;
  /// Voxels now free that were occupied, sorted (z, y, x).
  std::vector<octomap::OcTreeKey> vanished;
};

/// The changes confirmed after one sweep; regions in the (z, y, x) order of their first voxel.
struct ChangeSet final {
  std::uint64_t sweep = 0;  ///< 1 for the first sweep given to the detector
  std::vector<ChangeRegion> regions;
  [[nodiscard]] bool empty() const { return regions.empty(); }
};

/// Turns the voxel flips of each sweep (OccupancyUpdate) into confirmed change regions.
///
/// A voxel that flips becomes pending with the state it had before; it is confirmed once it has held its new
/// state for `persist_sweeps` sweeps, and dropped if it flips back first. Confirmed voxels of one sweep are
/// grouped by 26-connectivity; a group is reported when at least `min_voxels` of its voxels have no occupied
/// 26-neighbour that is itself unchanged (the others are surface jitter; so objects smaller than
/// `min_voxels` voxels off a surface go unreported). Voxels that appeared in a region reported within the
/// last 2 · persist_sweeps sweeps do not count as unchanged surface, so the parts of a new object that
/// collect their hits a little later (its sides, seen at grazing angles) are reported too instead of passing
/// for jitter on its top. A new object placed in observed free space is reported after
/// `OccupancyConfig::sweeps_to_occupy() + persist_sweeps - 1` sweeps that see it (5 with the defaults), and a
/// removed one after `OccupancyConfig::sweeps_to_clear() + persist_sweeps - 1` sweeps that see through where
/// it was (11 with the defaults). The first sweeps report the scene itself as appeared (a change from the
/// empty map). Not thread-safe; keep one detector per map.
class ChangeDetector final {
 public:
  /// @throws Error if `config` is invalid.
  explicit ChangeDetector(const ChangeConfig& config = {});

  /// Call once per sweep, right after `map.integrate(sweep)` returned `update`.
  [[nodiscard]] ChangeSet update(const OccupancyUpdate& update, const OccupancyMap& map);

  /// Voxels whose flip is still waiting for confirmation.
  [[nodiscard]] std::size_t pending() const { return pending_.size(); }
  /// The pending voxels that were occupied at their last confirmed state (free now, not yet confirmed so),
  /// sorted (z, y, x). If they fill again before confirmation, nothing is reported.
  [[nodiscard]] std::vector<octomap::OcTreeKey> pending_vanished() const;
  /// Takes the vanish of each pending voxel of `keys` that was occupied as confirmed, without reporting it:
  /// free is its confirmed state from now on, so filling again is a change (keys not pending so are left
  /// alone). For voxels whose boxes were dropped before the detector confirmed them gone: their object
  /// coming back must be reported, not taken for a flip back to the confirmed state.
  void accept_vanished(const std::vector<octomap::OcTreeKey>& keys);
  [[nodiscard]] const ChangeConfig& config() const { return config_; }

  /// Writes what the detector remembers between sweeps (the sweep count, the pending flips, the appeared
  /// voxels of recently reported regions) as text: a line `cellmap-change SWEEP PENDING REPORTED`, then one
  /// line per pending voxel (`x y z was_occupied sweeps_held`) and per reported voxel (`x y z sweep`), keys
  /// in (z, y, x) order. Saved with the map it belongs to, so that after a restart a flip seen before the
  /// map was saved still waits for confirmation instead of passing for the confirmed state.
  /// @throws Error if the stream fails.
  void write(std::ostream& out) const;
  /// Replaces the state with one written by write(). Flips that held longer than `persist_sweeps` (a
  /// config lowered meanwhile) are confirmed by the next update().
  /// @throws Error (the state unchanged) if the text is not such a state.
  void read(std::istream& in);

 private:
  struct Pending {
    bool was_occupied;  // the state before the flip (the last confirmed state)
    int sweeps;         // sweeps the new state has held, counting the flip's sweep
  };
  using KeySet = std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash>;
  // Voxels confirmed in this sweep → now occupied.
  using ConfirmedFlips = std::unordered_map<octomap::OcTreeKey, bool, octomap::OcTreeKey::KeyHash>;
  void record_flips(const OccupancyUpdate& update);
  [[nodiscard]] ConfirmedFlips confirm_held_flips();
  void forget_old_reports();
  [[nodiscard]] std::optional<ChangeRegion> grow_region(const octomap::OcTreeKey& seed,
                                                        const ConfirmedFlips& confirmed,
                                                        const OccupancyMap& map, KeySet& grouped);

  ChangeConfig config_;
  std::uint64_t sweep_ = 0;
  std::unordered_map<octomap::OcTreeKey, Pending, octomap::OcTreeKey::KeyHash> pending_;
  // Appeared voxels of reported regions → the sweep they were reported in, for 2 · persist_sweeps sweeps.
  std::unordered_map<octomap::OcTreeKey, std::uint64_t, octomap::OcTreeKey::KeyHash> reported_;
};

}  // namespace cellmap
