// SPDX-License-Identifier: Apache-2.0
#include "cellmap/unknown/unknown_boxes.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

// The voxels of `map` whose centres lie in `region`, those in `held_C` taken as needing no cover: marked
// occupied where unknown, which cover_unknown neither covers nor charges for.
VoxelStateGrid grid_of(const OccupancyMap& map, const Region& region, const std::vector<Box>& held_C) {
  VoxelStateGrid grid = VoxelStateGrid::of(map, region);
  const double r = grid.resolution();
  for (const Box& part : held_C) {
    const Eigen::Vector3d reach = part.rotation.toRotationMatrix().cwiseAbs() * part.half_extents;
    const Eigen::Vector3i low =
        ((part.center - reach - grid.origin()) / r).array().floor().cast<int>().max(0).matrix();
    const Eigen::Vector3i high = ((part.center + reach - grid.origin()) / r)
                                     .array()
                                     .ceil()
                                     .cast<int>()
                                     .min(grid.size().array())
                                     .matrix();
    for (int z = low.z(); z < high.z(); ++z) {
      for (int y = low.y(); y < high.y(); ++y) {
        for (int x = low.x(); x < high.x(); ++x) {
          const Eigen::Vector3d centre =
              grid.origin() + (Eigen::Vector3d(x, y, z).array() + 0.5).matrix() * r;
          if (grid.at(x, y, z) == VoxelState::unknown && part.contains(centre))
            grid.set(x, y, z, VoxelState::occupied);
        }
      }
    }
  }
  return grid;
}

// The voxels an axis-aligned box of whole voxels spans, as the region of their centres.
Region voxels_of(const Box& box, double resolution) {
  const Eigen::Vector3d inset = box.half_extents.array() - 0.5 * resolution;
  return {box.center - inset.cwiseMax(0.0), box.center + inset.cwiseMax(0.0)};
}

std::uint64_t unknown_voxels(const VoxelStateGrid& grid) {
  std::uint64_t count = 0;
  const Eigen::Vector3i& size = grid.size();
  for (int z = 0; z < size.z(); ++z) {
    for (int y = 0; y < size.y(); ++y) {
      for (int x = 0; x < size.x(); ++x) count += grid.at(x, y, z) == VoxelState::unknown;
    }
  }
  return count;
}

void sort_by_id(std::vector<Box>& boxes) {
  std::sort(boxes.begin(), boxes.end(), [](const Box& a, const Box& b) { return a.id < b.id; });
}

Region read_region(YamlMap section) {
  Region region{section.vector3("lower"), section.vector3("upper")};
  if ((region.min.array() >= region.max.array()).any())
    section.fail("upper", "must be > lower on every axis");
  section.expect_all_read();
  return region;
}

}  // namespace

void UnknownSpaceConfig::validate() const {
  cover.validate();
  if (check_sweeps < 1 || check_sweeps > 1000) {
    throw Error("unknown.check_sweeps: expected 1 to 1000, got " + std::to_string(check_sweeps));
  }
}

UnknownSpaceConfig UnknownSpaceConfig::from_yaml(YamlMap section) {
  UnknownSpaceConfig c;
  c.enabled = section.get<bool>("enabled", c.enabled);
  if (section.has("workspace")) c.workspace = read_region(section.child("workspace"));
  c.cover.min_size = section.number("min_size", c.cover.min_size, 0.0, 10.0);
  c.cover.max_free_share = section.number("max_free_share", c.cover.max_free_share, 0.0, 0.5);
  c.cover.max_boxes = static_cast<int>(section.integer("max_boxes", c.cover.max_boxes, 1, 10000));
  c.check_sweeps = static_cast<int>(section.integer("check_sweeps", c.check_sweeps, 1, 1000));
  section.expect_all_read();
  return c;
}

UnknownBoxes::UnknownBoxes(UnknownSpaceConfig config, std::vector<Box> boxes)
    : config_(std::move(config)), boxes_(std::move(boxes)) {
  config_.validate();
  if (!config_.active()) throw Error("unknown space: not enabled, or no workspace");
  for (Box& box : boxes_) box.space = BoxSpace::kUnknown;
  sort_by_id(boxes_);
}

UnknownChange UnknownBoxes::cover_all(const OccupancyMap& map, const std::vector<Box>& held_C,
                                      std::uint64_t& next_id) {
  last_cover_ = cover_unknown(grid_of(map, *config_.workspace, held_C), config_.cover);
  UnknownChange change;
  for (const Box& old : boxes_) change.removed.push_back(old.id);
  boxes_.clear();
  counted_.clear();
  for (Box box : last_cover_.boxes) {
    box.id = next_id++;
    boxes_.push_back(box);
    change.added.push_back(box);
  }
  return change;
}

UnknownChange UnknownBoxes::shrink(const OccupancyMap& map, const std::vector<Box>& held_C,
                                   std::uint64_t& next_id) {
  const double r = map.config().resolution;
  UnknownChange change;
  std::vector<Box> kept;
  for (std::size_t i = 0; i < boxes_.size(); ++i) {
    const Box& box = boxes_[i];
    const VoxelStateGrid grid = grid_of(map, voxels_of(box, r), held_C);
    const std::uint64_t left = unknown_voxels(grid);
    const auto counted = counted_.find(box.id);
    if (left >= (counted != counted_.end() ? counted->second : box.points)) {
      kept.push_back(box);  // nothing observed in it since it was last looked at
      continue;
    }
    UnknownConfig within = config_.cover;
    const int others = static_cast<int>(kept.size() + (boxes_.size() - i - 1));
    within.max_boxes = std::max(1, config_.cover.max_boxes - others);
    std::vector<Box> parts = cover_unknown(grid, within).boxes;
    if (parts.empty()) {
      change.removed.push_back(box.id);
      counted_.erase(box.id);
      continue;
    }
    if (!frees_a_cube(grid, parts, config_.cover.min_size)) {
      counted_[box.id] = left;  // observed inside, but nothing a limb could be in is free of it yet
      kept.push_back(box);
      continue;
    }
    std::stable_sort(parts.begin(), parts.end(),
                     [](const Box& a, const Box& b) { return a.volume() > b.volume(); });
    counted_.erase(box.id);
    parts[0].id = box.id;
    change.modified.push_back(parts[0]);
    for (std::size_t p = 1; p < parts.size(); ++p) {
      parts[p].id = next_id++;
      change.added.push_back(parts[p]);
    }
    kept.insert(kept.end(), parts.begin(), parts.end());
  }
  boxes_ = std::move(kept);
  sort_by_id(boxes_);
  return change;
}

}  // namespace cellmap
