// SPDX-License-Identifier: Apache-2.0
#include "cellmap/occupancy/occupancy_map.hpp"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>

#include "cellmap/common/error.hpp"
#include "key_update.hpp"
#include "tree_update.hpp"

namespace cellmap {
namespace {

// Sorts `keys` in (z, y, x) order by their values packed as z:y:x (cheaper than comparing key by key).
void sort_zyx(std::vector<octomap::OcTreeKey>& keys) {
  std::vector<std::uint64_t> packed(keys.size());
  std::transform(keys.begin(), keys.end(), packed.begin(), [](const octomap::OcTreeKey& k) {
    return std::uint64_t{k[0]} | (std::uint64_t{k[1]} << 16) | (std::uint64_t{k[2]} << 32);
  });
  std::sort(packed.begin(), packed.end());
  std::transform(packed.begin(), packed.end(), keys.begin(), [](std::uint64_t p) {
    return octomap::OcTreeKey(static_cast<octomap::key_type>(p & 0xffff),
                              static_cast<octomap::key_type>((p >> 16) & 0xffff),
                              static_cast<octomap::key_type>(p >> 32));
  });
}

// OctoMap's node data as OcTree::writeData writes it (each node its log-odds as a float, then a byte that
// says which of its eight children follow, depth first), read from `in` and checked before OcTree::readData
// sees it: readData recurses once per level, reads on past the end of a truncated stream, and takes one
// coarse occupied node for every voxel below it. @throws Error unless the data ends within `in`, no node lies
// deeper than `depth`, every log-odds is finite, and the occupied leaves (log-odds at least
// `occupied_log_odds`) stand for at most `max_occupied` voxels of the finest level.
std::string checked_node_data(std::istream& in, unsigned depth, float occupied_log_odds,
                              std::uint64_t max_occupied) {
  constexpr std::size_t kNodeBytes = sizeof(float) + 1;
  std::string data;
  std::uint64_t occupied = 0;
  std::vector<int> children_left{1};  // per level on the path from the root: nodes still to read
  while (!children_left.empty()) {
    if (children_left.back() == 0) {
      children_left.pop_back();
      continue;
    }
    --children_left.back();
    const unsigned level = static_cast<unsigned>(children_left.size()) - 1;
    char node[kNodeBytes];
    if (!in.read(node, kNodeBytes)) throw Error("occupancy map: the saved map is truncated");
    data.append(node, kNodeBytes);
    float log_odds = 0;
    std::memcpy(&log_odds, node, sizeof log_odds);
    if (!std::isfinite(log_odds))
      throw Error("occupancy map: the saved map holds a log-odds that is not finite");
    const int children = std::bitset<8>(static_cast<unsigned char>(node[sizeof(float)])).count();
    if (children > 0 && level == depth) throw Error("occupancy map: the saved map is deeper than the tree");
    if (children == 0 && log_odds >= occupied_log_odds) occupied += std::uint64_t{1} << (3 * (depth - level));
    if (occupied > max_occupied) {
      throw Error("occupancy map: the saved map holds more than " + std::to_string(max_occupied) +
                  " occupied voxels (OccupancyMap::kMaxSavedOccupiedVoxels)");
    }
    if (children > 0) children_left.push_back(children);
  }
  return data;
}

}  // namespace

void apply_sensor_model(const OccupancyConfig& config, octomap::OcTree& tree) {
  tree.setProbHit(config.hit);
  tree.setProbMiss(config.miss);
  tree.setClampingThresMin(config.clamp_min);
  tree.setClampingThresMax(config.clamp_max);
  tree.setOccupancyThres(config.occupied_threshold);
}

OccupancyMap::OccupancyMap(const OccupancyConfig& config) : config_(config) {
  config_.validate();
  tree_ = std::make_unique<octomap::OcTree>(config_.resolution);
  apply_sensor_model(config_, *tree_);
}

ObservedVoxels::ObservedVoxels(const OccupancyConfig& config)
    : config_(config), union_(std::make_unique<KeyUpdateUnion>()) {
  config_.validate();
  grid_ = std::make_unique<octomap::OcTree>(config_.resolution);
}

ObservedVoxels::~ObservedVoxels() = default;
ObservedVoxels::ObservedVoxels(ObservedVoxels&&) noexcept = default;
ObservedVoxels& ObservedVoxels::operator=(ObservedVoxels&&) noexcept = default;

void ObservedVoxels::add(Scan scan, int threads) {
  Sweep one;
  one.scans.push_back(std::move(scan));
  union_->add(compute_key_update(one, *grid_, config_.max_range, threads > 0 ? threads : config_.threads));
  ++scans_;
}

void ObservedVoxels::merge(ObservedVoxels& other) {
  if (other.config_.resolution != config_.resolution || other.config_.max_range != config_.max_range)
    throw Error("occupancy: voxels gathered at another resolution or range cannot be merged");
  union_->merge(*other.union_);
  scans_ += std::exchange(other.scans_, 0);
}

std::size_t ObservedVoxels::bricks() const {
  return union_->size();
}

OccupancyUpdate OccupancyMap::integrate(const Sweep& sweep) {
  return apply(compute_key_update(sweep, *tree_, config_.max_range, config_.threads));
}

OccupancyUpdate OccupancyMap::integrate(ObservedVoxels& voxels) {
  if (voxels.config_.resolution != config_.resolution) {
    throw Error("occupancy: voxels gathered at resolution " + std::to_string(voxels.config_.resolution) +
                " m cannot be fused into a map of " + std::to_string(config_.resolution) + " m");
  }
  voxels.scans_ = 0;
  return apply(voxels.union_->take());
}

OccupancyUpdate OccupancyMap::apply(const KeyUpdate& keys) {
  OccupancyUpdate update;
  update.hit_voxels = keys.occupied_count;
  update.free_voxels = keys.free_count;
  apply_key_update(keys, *tree_, update);
  sort_zyx(update.appeared);
  sort_zyx(update.vanished);
  return update;
}

std::size_t OccupancyMap::mark_occupied(const std::vector<Eigen::Vector3d>& points_C) {
  const float occupied = octomap::logodds(config_.clamp_max);
  std::size_t outside = 0;
  for (const Eigen::Vector3d& p : points_C) {
    octomap::OcTreeKey key;
    if (!p.allFinite()) continue;
    if (tree_->coordToKeyChecked(p.x(), p.y(), p.z(), key)) {
      tree_->setNodeValue(key, occupied, true);
    } else {
      ++outside;
    }
  }
  tree_->updateInnerOccupancy();
  return outside;
}

VoxelState OccupancyMap::state(const Eigen::Vector3d& p_C) const {
  octomap::OcTreeKey key;
  if (!p_C.allFinite() || !tree_->coordToKeyChecked(p_C.x(), p_C.y(), p_C.z(), key))
    return VoxelState::unknown;
  return state(key);
}

VoxelState OccupancyMap::state(const octomap::OcTreeKey& key) const {
  const octomap::OcTreeNode* node = tree_->search(key);
  if (node == nullptr) return VoxelState::unknown;
  return tree_->isNodeOccupied(node) ? VoxelState::occupied : VoxelState::free;
}

Eigen::Vector3d OccupancyMap::centre(const octomap::OcTreeKey& key) const {
  return {tree_->keyToCoord(key[0]), tree_->keyToCoord(key[1]), tree_->keyToCoord(key[2])};
}

namespace {

// Appends the leaf keys of the occupied leaves (pruned ones expanded) that `begin`..`end` visit.
template <class Iterator>
void append_occupied(const octomap::OcTree& tree, Iterator begin, Iterator end,
                     std::vector<octomap::OcTreeKey>& keys) {
  const unsigned depth = tree.getTreeDepth();
  for (auto it = begin; it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    if (it.getDepth() == depth) {
      keys.push_back(it.getKey());
      continue;
    }
    // A pruned leaf stands for a block of equal voxels: list each.
    const int span = 1 << (depth - it.getDepth());
    const octomap::OcTreeKey first = it.getIndexKey();
    for (int z = 0; z < span; ++z)
      for (int y = 0; y < span; ++y)
        for (int x = 0; x < span; ++x) keys.emplace_back(first[0] + x, first[1] + y, first[2] + z);
  }
  sort_zyx(keys);
}

}  // namespace

std::vector<octomap::OcTreeKey> OccupancyMap::occupied_keys() const {
  std::vector<octomap::OcTreeKey> keys;
  append_occupied(*tree_, tree_->begin_leafs(), tree_->end_leafs(), keys);
  return keys;
}

std::vector<Eigen::Vector3d> OccupancyMap::occupied_centres_in(const Eigen::Vector3d& min_C,
                                                               const Eigen::Vector3d& max_C) const {
  std::vector<Eigen::Vector3d> centres;
  if (!min_C.allFinite() || !max_C.allFinite() || (min_C.array() > max_C.array()).any()) return centres;
  const octomap::point3d lo(float(min_C.x()), float(min_C.y()), float(min_C.z()));
  const octomap::point3d hi(float(max_C.x()), float(max_C.y()), float(max_C.z()));
  std::vector<octomap::OcTreeKey> keys;
  append_occupied(*tree_, tree_->begin_leafs_bbx(lo, hi), tree_->end_leafs_bbx(), keys);
  for (const octomap::OcTreeKey& key : keys) {
    const Eigen::Vector3d c = centre(key);
    if ((c.array() >= min_C.array()).all() && (c.array() <= max_C.array()).all()) centres.push_back(c);
  }
  return centres;
}

}  // namespace cellmap

namespace cellmap {

std::vector<Eigen::Vector3d> OccupancyMap::occupied_centres(const std::vector<Region>& regions) const {
  std::vector<octomap::OcTreeKey> keys;
  for (const Region& region : regions) {
    if (region.volume() <= 0) continue;
    const octomap::point3d min(static_cast<float>(region.min.x()), static_cast<float>(region.min.y()),
                               static_cast<float>(region.min.z()));
    const octomap::point3d max(static_cast<float>(region.max.x()), static_cast<float>(region.max.y()),
                               static_cast<float>(region.max.z()));
    for (auto it = tree_->begin_leafs_bbx(min, max), end = tree_->end_leafs_bbx(); it != end; ++it) {
      if (!tree_->isNodeOccupied(*it)) continue;
      // Pruned leaves stand for several voxels: enumerate the leaf-level keys they cover.
      const int span = 1 << (tree_->getTreeDepth() - it.getDepth());
      const octomap::OcTreeKey base = it.getIndexKey();
      for (int dz = 0; dz < span; ++dz) {
        for (int dy = 0; dy < span; ++dy) {
          for (int dx = 0; dx < span; ++dx) {
            const octomap::OcTreeKey key(base[0] + dx, base[1] + dy, base[2] + dz);
            if (region.contains(centre(key))) keys.push_back(key);
          }
        }
      }
    }
  }
  const auto zyx = [](const octomap::OcTreeKey& a, const octomap::OcTreeKey& b) {
    return std::tie(a[2], a[1], a[0]) < std::tie(b[2], b[1], b[0]);
  };
  std::sort(keys.begin(), keys.end(), zyx);
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(keys.size());
  for (const auto& key : keys) centres.push_back(centre(key));
  return centres;
}

bool OccupancyMap::any_occupied_in(
    const Region& region,
    const std::function<bool(const octomap::OcTreeKey& key, const Eigen::Vector3d& centre_C)>& accept) const {
  if (region.volume() <= 0) return false;
  const octomap::point3d min(static_cast<float>(region.min.x()), static_cast<float>(region.min.y()),
                             static_cast<float>(region.min.z()));
  const octomap::point3d max(static_cast<float>(region.max.x()), static_cast<float>(region.max.y()),
                             static_cast<float>(region.max.z()));
  for (auto it = tree_->begin_leafs_bbx(min, max), end = tree_->end_leafs_bbx(); it != end; ++it) {
    if (!tree_->isNodeOccupied(*it)) continue;
    // A pruned leaf stands for a block of equal voxels: each one is asked.
    const int span = 1 << (tree_->getTreeDepth() - it.getDepth());
    const octomap::OcTreeKey base = it.getIndexKey();
    for (int dz = 0; dz < span; ++dz) {
      for (int dy = 0; dy < span; ++dy) {
        for (int dx = 0; dx < span; ++dx) {
          const octomap::OcTreeKey key(base[0] + dx, base[1] + dy, base[2] + dz);
          const Eigen::Vector3d c = centre(key);
          if (region.contains(c) && accept(key, c)) return true;
        }
      }
    }
  }
  return false;
}

void OccupancyMap::write(std::ostream& out) const {
  out.precision(17);
  out << "cellmap-occupancy resolution " << config_.resolution << "\n";
  tree_->writeData(out);
  if (!out) throw Error("occupancy map: writing the map failed");
}

void OccupancyMap::read(std::istream& in) {
  std::string magic, word;
  double resolution = 0;
  if (!(in >> magic >> word >> resolution) || magic != "cellmap-occupancy" || word != "resolution" ||
      in.get() != '\n') {
    throw Error("occupancy map: not a saved cellmap occupancy map");
  }
  if (std::abs(resolution - config_.resolution) > 1e-12) {
    throw Error("occupancy map: the saved map has resolution " + std::to_string(resolution) +
                " m, the config says " + std::to_string(config_.resolution) + " m");
  }
  auto tree = std::make_unique<octomap::OcTree>(config_.resolution);
  apply_sensor_model(config_, *tree);
  // An empty map is written as no node at all.
  if (in.peek() != std::char_traits<char>::eof()) {
    std::istringstream nodes(
        checked_node_data(in, tree->getTreeDepth(), tree->getOccupancyThresLog(), kMaxSavedOccupiedVoxels));
    tree->readData(nodes);
  }
  tree_ = std::move(tree);
}

}  // namespace cellmap
