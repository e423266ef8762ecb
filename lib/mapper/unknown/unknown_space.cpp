// SPDX-License-Identifier: Apache-2.0
#include "cellmap/unknown/unknown_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

constexpr std::size_t kMaxGridVoxels = std::size_t{1} << 27;

// A box of voxel indices [low, high).
struct IndexBox {
  Eigen::Vector3i low;
  Eigen::Vector3i high;

  [[nodiscard]] long long voxels() const {
    const Eigen::Vector3i extent = (high - low).cwiseMax(0);
    return static_cast<long long>(extent.x()) * extent.y() * extent.z();
  }
  [[nodiscard]] IndexBox joined(const IndexBox& other) const {
    return {low.cwiseMin(other.low), high.cwiseMax(other.high)};
  }
  [[nodiscard]] IndexBox overlap(const IndexBox& other) const {
    return {low.cwiseMax(other.low), high.cwiseMin(other.high)};
  }
  [[nodiscard]] bool holds(const IndexBox& other) const {
    return (low.array() <= other.low.array()).all() && (high.array() >= other.high.array()).all();
  }
};

// Counts of a voxel predicate over any box of the grid in constant time (a summed-volume table).
class VoxelCounts {
 public:
  template <typename Predicate>
  VoxelCounts(const Eigen::Vector3i& size, Predicate counts)
      : size_(size), sums_(static_cast<std::size_t>(size.x() + 1) * (size.y() + 1) * (size.z() + 1), 0) {
    for (int z = 0; z < size.z(); ++z) {
      for (int y = 0; y < size.y(); ++y) {
        for (int x = 0; x < size.x(); ++x) {
          sum(x + 1, y + 1, z + 1) = (counts(x, y, z) ? 1 : 0) + sum(x, y + 1, z + 1) + sum(x + 1, y, z + 1) +
                                     sum(x + 1, y + 1, z) - sum(x, y, z + 1) - sum(x, y + 1, z) -
                                     sum(x + 1, y, z) + sum(x, y, z);
        }
      }
    }
  }

  // The count over `box` clipped to the grid.
  [[nodiscard]] long long in(const IndexBox& box) const {
    const Eigen::Vector3i l = box.low.cwiseMax(0);
    const Eigen::Vector3i h = box.high.cwiseMin(size_);
    if ((h.array() <= l.array()).any()) return 0;
    return at(h.x(), h.y(), h.z()) - at(l.x(), h.y(), h.z()) - at(h.x(), l.y(), h.z()) -
           at(h.x(), h.y(), l.z()) + at(l.x(), l.y(), h.z()) + at(l.x(), h.y(), l.z()) +
           at(h.x(), l.y(), l.z()) - at(l.x(), l.y(), l.z());
  }

 private:
  [[nodiscard]] std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * (size_.y() + 1) + y) * (size_.x() + 1) + x;
  }
  long long& sum(int x, int y, int z) { return sums_[index(x, y, z)]; }
  [[nodiscard]] long long at(int x, int y, int z) const { return sums_[index(x, y, z)]; }

  Eigen::Vector3i size_;
  std::vector<long long> sums_;
};

// One byte a voxel, true where a predicate holds.
using VoxelMask = std::vector<unsigned char>;

std::size_t mask_index(const Eigen::Vector3i& size, int x, int y, int z) {
  return (static_cast<std::size_t>(z) * size.y() + y) * size.x() + x;
}

// A length in whole voxels, at least one.
int cube_edge(double length, double resolution) {
  return std::max(1, static_cast<int>(std::ceil(length / resolution - 1e-9)));
}

// The unknown voxels that some all-unknown cube of `edge` voxels holds: the pockets worth covering.
VoxelMask pockets(const VoxelStateGrid& grid, const VoxelCounts& unknown, int edge) {
  const Eigen::Vector3i& size = grid.size();
  const long long full = static_cast<long long>(edge) * edge * edge;
  const Eigen::Vector3i cube = Eigen::Vector3i::Constant(edge);
  // A cube fits with its low corner at v.
  const VoxelCounts fits(size, [&](int x, int y, int z) {
    const Eigen::Vector3i v(x, y, z);
    return (v + cube).cwiseMin(size) == v + cube && unknown.in({v, v + cube}) == full;
  });
  VoxelMask mask(grid.voxel_count(), 0);
  for (int z = 0; z < size.z(); ++z) {
    for (int y = 0; y < size.y(); ++y) {
      for (int x = 0; x < size.x(); ++x) {
        const Eigen::Vector3i v(x, y, z);
        mask[mask_index(size, x, y, z)] =
            fits.in({v - cube + Eigen::Vector3i::Ones(), v + Eigen::Vector3i::Ones()}) > 0;
      }
    }
  }
  return mask;
}

// The layer of voxels just outside `box` on side `side` (0..5: −x, +x, −y, +y, −z, +z), or an empty box at
// the grid's border.
IndexBox layer_beside(const IndexBox& box, int side, const Eigen::Vector3i& size) {
  const int axis = side / 2;
  IndexBox layer = box;
  if (side % 2 == 0) {
    if (box.low[axis] == 0) return {box.low, box.low};
    layer.low[axis] = box.low[axis] - 1;
    layer.high[axis] = box.low[axis];
  } else {
    if (box.high[axis] == size[axis]) return {box.low, box.low};
    layer.low[axis] = box.high[axis];
    layer.high[axis] = box.high[axis] + 1;
  }
  return layer;
}

struct CoverCounts {
  VoxelCounts pocket;
  VoxelCounts free;
};

// The box grown from voxel `seed` one layer at a time, on every side in turn, while a layer holds pocket
// voxels and at most `max_free_share` of it is seen free.
IndexBox grown_from(const Eigen::Vector3i& seed, const Eigen::Vector3i& size, const CoverCounts& counts,
                    double max_free_share) {
  IndexBox box{seed, seed + Eigen::Vector3i::Ones()};
  for (bool grew = true; grew;) {
    grew = false;
    for (int side = 0; side < 6; ++side) {
      const IndexBox layer = layer_beside(box, side, size);
      if (layer.voxels() == 0 || counts.pocket.in(layer) == 0) continue;
      if (static_cast<double>(counts.free.in(layer)) > max_free_share * static_cast<double>(layer.voxels())) {
        continue;
      }
      box = box.joined(layer);
      grew = true;
    }
  }
  return box;
}

std::vector<IndexBox> grow_boxes(const VoxelMask& pocket, const Eigen::Vector3i& size,
                                 const CoverCounts& counts, double max_free_share) {
  VoxelMask covered(pocket.size(), 0);
  std::vector<IndexBox> boxes;
  for (int z = 0; z < size.z(); ++z) {
    for (int y = 0; y < size.y(); ++y) {
      for (int x = 0; x < size.x(); ++x) {
        const std::size_t i = mask_index(size, x, y, z);
        if (!pocket[i] || covered[i]) continue;
        const IndexBox box = grown_from({x, y, z}, size, counts, max_free_share);
        for (int bz = box.low.z(); bz < box.high.z(); ++bz) {
          for (int by = box.low.y(); by < box.high.y(); ++by) {
            for (int bx = box.low.x(); bx < box.high.x(); ++bx) covered[mask_index(size, bx, by, bz)] = 1;
          }
        }
        boxes.push_back(box);
      }
    }
  }
  return boxes;
}

// Seen free voxels that joining a and b adds to what the two already block.
long long free_added(const IndexBox& a, const IndexBox& b, const VoxelCounts& free) {
  return free.in(a.joined(b)) - free.in(a)-free.in(b) + free.in(a.overlap(b));
}

void drop_boxes_held_by_others(std::vector<IndexBox>& boxes) {
  std::vector<IndexBox> kept;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    bool held = false;
    for (std::size_t j = 0; j < boxes.size() && !held; ++j) {
      // Of two equal boxes the first stays.
      held = j != i && boxes[j].holds(boxes[i]) && (!boxes[i].holds(boxes[j]) || j < i);
    }
    if (!held) kept.push_back(boxes[i]);
  }
  boxes = std::move(kept);
}

// Joins the pair that adds the least seen free space while that is within max_free_share of the space the
// join adds, or while there are more than max_boxes.
void join_boxes(std::vector<IndexBox>& boxes, const VoxelCounts& free, const UnknownConfig& config) {
  drop_boxes_held_by_others(boxes);
  while (boxes.size() > 1) {
    long long best_cost = std::numeric_limits<long long>::max();
    std::size_t best_i = 0, best_j = 0;
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      for (std::size_t j = i + 1; j < boxes.size(); ++j) {
        const long long cost = free_added(boxes[i], boxes[j], free);
        if (cost < best_cost) best_cost = cost, best_i = i, best_j = j;
      }
    }
    const IndexBox& a = boxes[best_i];
    const IndexBox& b = boxes[best_j];
    const IndexBox joined = a.joined(b);
    // Measured against the space the join adds, as a layer's growth is: against the joined box, two large
    // boxes would take in a free gap between them that a limb could be in.
    const long long added = joined.voxels() - a.voxels() - b.voxels() + a.overlap(b).voxels();
    const bool cheap = static_cast<double>(best_cost) <= config.max_free_share * static_cast<double>(added);
    if (!cheap && static_cast<int>(boxes.size()) <= config.max_boxes) break;
    boxes[best_i] = joined;
    boxes.erase(boxes.begin() + static_cast<std::ptrdiff_t>(best_j));
    drop_boxes_held_by_others(boxes);
  }
}

Box to_box(const IndexBox& box, const VoxelStateGrid& grid, const VoxelCounts& unknown) {
  const double r = grid.resolution();
  Box out;
  const Eigen::Vector3d low = grid.origin() + box.low.cast<double>() * r;
  const Eigen::Vector3d high = grid.origin() + box.high.cast<double>() * r;
  out.center = 0.5 * (low + high);
  out.half_extents = 0.5 * (high - low);
  out.points = static_cast<std::uint64_t>(unknown.in(box));
  out.space = BoxSpace::kUnknown;
  return out;
}

// Voxels inside some box: (all of them, the seen free ones).
std::pair<long long, long long> boxed_voxels(const std::vector<IndexBox>& boxes, const VoxelStateGrid& grid) {
  const Eigen::Vector3i& size = grid.size();
  VoxelMask boxed(grid.voxel_count(), 0);
  long long all = 0, free = 0;
  for (const IndexBox& box : boxes) {
    for (int z = box.low.z(); z < box.high.z(); ++z) {
      for (int y = box.low.y(); y < box.high.y(); ++y) {
        for (int x = box.low.x(); x < box.high.x(); ++x) {
          unsigned char& seen = boxed[mask_index(size, x, y, z)];
          if (seen) continue;
          seen = 1;
          ++all;
          if (grid.at(x, y, z) == VoxelState::free) ++free;
        }
      }
    }
  }
  return {all, free};
}

}  // namespace

void UnknownConfig::validate() const {
  if (!std::isfinite(min_size) || min_size < 0.0 || min_size > 10.0) {
    throw Error("unknown.min_size: expected 0 to 10 m, got " + std::to_string(min_size));
  }
  if (!std::isfinite(max_free_share) || max_free_share < 0.0 || max_free_share > 0.5) {
    throw Error("unknown.max_free_share: expected 0 to 0.5, got " + std::to_string(max_free_share));
  }
  if (max_boxes < 1 || max_boxes > 10000) {
    throw Error("unknown.max_boxes: expected 1 to 10000, got " + std::to_string(max_boxes));
  }
}

VoxelStateGrid::VoxelStateGrid(const Eigen::Vector3i& size, double resolution,
                               const Eigen::Vector3d& origin_C)
    : size_(size), resolution_(resolution), origin_(origin_C) {
  if ((size.array() < 1).any()) throw Error("voxel grid: every size must be at least 1");
  if (!(resolution > 0.0) || !std::isfinite(resolution)) throw Error("voxel grid: resolution must be > 0");
  const double voxels = static_cast<double>(size.x()) * size.y() * size.z();
  if (voxels > static_cast<double>(kMaxGridVoxels)) {
    throw Error("voxel grid: " + std::to_string(static_cast<long long>(voxels)) + " voxels, more than 2^27");
  }
  states_.assign(static_cast<std::size_t>(voxels), VoxelState::unknown);
}

void VoxelStateGrid::fill(const Eigen::Vector3i& low, const Eigen::Vector3i& high, VoxelState state) {
  const Eigen::Vector3i l = low.cwiseMax(0);
  const Eigen::Vector3i h = high.cwiseMin(size_);
  for (int z = l.z(); z < h.z(); ++z) {
    for (int y = l.y(); y < h.y(); ++y) {
      for (int x = l.x(); x < h.x(); ++x) set(x, y, z, state);
    }
  }
}

VoxelStateGrid VoxelStateGrid::of(const OccupancyMap& map, const Region& workspace) {
  if (!workspace.min.allFinite() || !workspace.max.allFinite() || workspace.volume() <= 0.0) {
    throw Error("unknown space: the workspace is empty or not finite");
  }
  const octomap::OcTree& tree = map.tree();
  const double r = tree.getResolution();
  octomap::OcTreeKey low_key, high_key;
  if (!tree.coordToKeyChecked(workspace.min.x(), workspace.min.y(), workspace.min.z(), low_key) ||
      !tree.coordToKeyChecked(workspace.max.x(), workspace.max.y(), workspace.max.z(), high_key)) {
    throw Error("unknown space: the workspace reaches past the map's key range");
  }
  const Eigen::Vector3i size(high_key[0] - low_key[0] + 1, high_key[1] - low_key[1] + 1,
                             high_key[2] - low_key[2] + 1);
  VoxelStateGrid grid(size, r, map.centre(low_key) - Eigen::Vector3d::Constant(0.5 * r));
  for (auto it = tree.begin_leafs_bbx(low_key, high_key), end = tree.end_leafs_bbx(); it != end; ++it) {
    const VoxelState state = tree.isNodeOccupied(*it) ? VoxelState::occupied : VoxelState::free;
    const double half = 0.5 * it.getSize();
    const Eigen::Vector3d centre(it.getX(), it.getY(), it.getZ());
    // The leaf spans voxels whose centres lie within half its size of its centre.
    const Eigen::Vector3d low_centre = centre - Eigen::Vector3d::Constant(half - 0.5 * r);
    const Eigen::Vector3i low = ((low_centre - grid.origin()) / r).array().floor().cast<int>();
    const int voxels = static_cast<int>(std::lround(it.getSize() / r));
    grid.fill(low, low + Eigen::Vector3i::Constant(voxels), state);
  }
  return grid;
}

bool frees_a_cube(const VoxelStateGrid& grid, const std::vector<Box>& boxes, double edge_m) {
  const Eigen::Vector3i& size = grid.size();
  const int edge = cube_edge(edge_m, grid.resolution());
  const auto centre = [&](int x, int y, int z) {
    return Eigen::Vector3d(grid.origin() +
                           (Eigen::Vector3d(x, y, z).array() + 0.5).matrix() * grid.resolution());
  };
  const VoxelCounts freed(size, [&](int x, int y, int z) {
    const Eigen::Vector3d c = centre(x, y, z);
    return std::none_of(boxes.begin(), boxes.end(), [&](const Box& box) { return box.contains(c); });
  });
  const long long full = static_cast<long long>(edge) * edge * edge;
  const Eigen::Vector3i cube = Eigen::Vector3i::Constant(edge);
  for (int z = 0; z + edge <= size.z(); ++z) {
    for (int y = 0; y + edge <= size.y(); ++y) {
      for (int x = 0; x + edge <= size.x(); ++x) {
        const Eigen::Vector3i v(x, y, z);
        if (freed.in({v, v + cube}) == full) return true;
      }
    }
  }
  return false;
}

UnknownCover cover_unknown(const VoxelStateGrid& grid, const UnknownConfig& config) {
  config.validate();
  const Eigen::Vector3i& size = grid.size();
  const int edge = cube_edge(config.min_size, grid.resolution());
  const VoxelCounts unknown(size,
                            [&](int x, int y, int z) { return grid.at(x, y, z) == VoxelState::unknown; });
  const VoxelMask pocket = pockets(grid, unknown, edge);
  const CoverCounts counts{
      VoxelCounts(size, [&](int x, int y, int z) { return pocket[mask_index(size, x, y, z)] != 0; }),
      VoxelCounts(size, [&](int x, int y, int z) { return grid.at(x, y, z) == VoxelState::free; })};
  std::vector<IndexBox> boxes = grow_boxes(pocket, size, counts, config.max_free_share);
  join_boxes(boxes, counts.free, config);
  std::sort(boxes.begin(), boxes.end(), [](const IndexBox& a, const IndexBox& b) {
    return std::make_tuple(a.low.z(), a.low.y(), a.low.x()) <
           std::make_tuple(b.low.z(), b.low.y(), b.low.x());
  });

  const double voxel_volume = std::pow(grid.resolution(), 3);
  const IndexBox whole{Eigen::Vector3i::Zero(), size};
  UnknownCover cover;
  for (const IndexBox& box : boxes) cover.boxes.push_back(to_box(box, grid, unknown));
  const auto [boxed, blocked_free] = boxed_voxels(boxes, grid);
  cover.grid_volume = static_cast<double>(whole.voxels()) * voxel_volume;
  cover.unknown_volume = static_cast<double>(unknown.in(whole)) * voxel_volume;
  cover.ignored_volume = static_cast<double>(unknown.in(whole)-counts.pocket.in(whole)) * voxel_volume;
  cover.blocked_free_volume = static_cast<double>(blocked_free) * voxel_volume;
  cover.boxed_volume = static_cast<double>(boxed) * voxel_volume;
  return cover;
}

}  // namespace cellmap
