// SPDX-License-Identifier: Apache-2.0
#pragma once
// The unknown boxes of one cell over time: made once from the settled map, then only ever shrunk as sensors
// look into them, so that unknown space never reappears where it was once seen (until the map is reset).

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/common/region.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/unknown/unknown_space.hpp"

namespace cellmap {

/// Where and how a cell tracks unknown space (YAML section `unknown`; docs/environment.md#unknown-space).
struct UnknownSpaceConfig final {
  /// Whether unknown boxes are published at all (`unknown.enabled`; default true: a planner must not take
  /// space nobody looked at for free). Needs a workspace.
  bool enabled = true;
  /// The region in which unknown space matters, cell frame (`unknown.workspace: {lower, upper}`); absent:
  /// the bounds of `segment.workspace`; neither: unknown space is not tracked (active() is false).
  std::optional<Region> workspace;
  UnknownConfig cover;  ///< `unknown.min_size`, `unknown.max_free_share`, `unknown.max_boxes`
  /// Sweeps that voxels never observed before wait to be checked for whether a box shrank, unless a change
  /// is re-segmented first, which checks them with it (`unknown.check_sweeps`, [1, 1000]; default 8). Above
  /// change.persist_sweeps + change.gather_sweeps, an object that comes into view together with the unknown
  /// space behind it (a crate taken away) is one version. A check costs a pass over the unknown boxes'
  /// voxels.
  int check_sweeps = 8;

  [[nodiscard]] bool active() const { return enabled && workspace.has_value(); }
  /// @throws Error naming the key ("unknown.check_sweeps: ...") if a value is out of range.
  void validate() const;
  /// Reads the `unknown` section (absent keys keep their defaults) and marks it read. Keys: enabled,
  /// workspace {lower, upper}, min_size, max_free_share, max_boxes, check_sweeps.
  /// @throws Error naming the key for unknown keys, wrong types or bad ranges.
  [[nodiscard]] static UnknownSpaceConfig from_yaml(YamlMap section);
};

/// What one call changed among the unknown boxes (every box of space BoxSpace::kUnknown).
struct UnknownChange final {
  std::vector<Box> added;
  std::vector<Box> modified;
  std::vector<std::uint64_t> removed;
  [[nodiscard]] bool empty() const { return added.empty() && modified.empty() && removed.empty(); }
};

/// The unknown boxes of one cell. Each box's `points` is the number of unknown voxels it held when it was
/// made. Unknown voxels inside `held_C` (boxes in the cell frame) need no unknown box:
/// - the obstacle boxes: they block those voxels already (an object's inside is never observed);
/// - the robot's body: its own points are cut out of every frame, so the space it stands in is never
///   observed, yet nothing can hide where the robot is, and a planner has its robot's model.
/// Not thread-safe.
class UnknownBoxes final {
 public:
  /// Starts from the unknown boxes the cell published last (restored from its state), or none.
  /// @throws Error if the config is invalid or not active().
  explicit UnknownBoxes(UnknownSpaceConfig config, std::vector<Box> boxes = {});

  /// Covers the workspace's unknown voxels from scratch (cover_unknown), replacing every box: for the first
  /// version of a map. New boxes take ids from `next_id` on, which is advanced.
  UnknownChange cover_all(const OccupancyMap& map, const std::vector<Box>& held_C, std::uint64_t& next_id);
  /// Covers again, within its own extent, every box in which voxels were observed since it was last looked
  /// at, and takes the new cover when it frees a cube of `min_size` (space a limb could be in; a few voxels
  /// seen at a box's side through noise free none): the largest new box keeps the old id, the others take
  /// new ids from `next_id`, and a box with nothing left to cover goes. Boxes never grow. The count of boxes
  /// stays within `max_boxes` where the boxes left allow.
  UnknownChange shrink(const OccupancyMap& map, const std::vector<Box>& held_C, std::uint64_t& next_id);

  /// The current boxes, sorted by id.
  [[nodiscard]] const std::vector<Box>& boxes() const { return boxes_; }
  /// The figures of the last cover_all() (all zero before one, and after a restart until one).
  [[nodiscard]] const UnknownCover& last_cover() const { return last_cover_; }
  [[nodiscard]] const UnknownSpaceConfig& config() const { return config_; }

 private:
  UnknownSpaceConfig config_;
  std::vector<Box> boxes_;
  // Unknown voxels counted in a box when its new cover freed nothing: a box is looked at again once fewer are
  // left (else once fewer than its `points` are).
  std::map<std::uint64_t, std::uint64_t> counted_;
  UnknownCover last_cover_;
};

}  // namespace cellmap
