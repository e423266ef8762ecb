#include "cellmap/occupancy/occupancy_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <tuple>

#include "cellmap/common/error.hpp"
#include "key_update.hpp"

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

// Applies a KeyUpdate to an OcTree brick by brick, descending each subtree once instead of once per voxel.
// Written here because OctoMap has no batch update: per voxel, updateNode() searches the key from the root
// and descends again (≈ 0.3 µs per voxel, ~1.6 M free voxels per 640×480 frame). This walk follows
// updateNode(key, occupied, lazy_eval = true)'s rules exactly — the early abort for voxels already at the
// clamp bound (it neither expands nor creates nodes for them), expanding pruned nodes, creating missing
// children with log-odds 0, clamped log-odds updates — so every leaf ends as updateNode() would leave it.
// Instead of one updateInnerOccupancy() over the whole tree, it refreshes the inner nodes it visited (the
// others did not change) and prunes them as OctoMap's non-lazy insert does, so free space stays compact.
class BatchApplier {
 public:
  BatchApplier(octomap::OcTree& tree, OccupancyUpdate& out)
      : tree_(tree),
        out_(out),
        depth_(tree.getTreeDepth()),
        hit_(tree.getProbHitLog()),
        miss_(tree.getProbMissLog()),
        clamp_min_(tree.getClampingThresMinLog()),
        clamp_max_(tree.getClampingThresMaxLog()) {}

  void apply(KeyBrick brick) {
    if (tree_.getRoot() == nullptr) {
      // The root can only be created through updateNode(); let it apply the brick's first voxel (non-lazy so
      // that the path's inner values are right), then batch the rest.
      const bool occupied = any(brick.occupied, 0, KeyBrick::kVoxels);
      auto& words = occupied ? brick.occupied : brick.free;
      const int first = first_bit(words);
      const octomap::OcTreeKey key = brick.key(first);
      words[std::size_t(first >> 6)] &= ~(std::uint64_t{1} << (first & 63));
      const octomap::OcTreeNode* node = tree_.updateNode(key, occupied, false);
      if (occupied && tree_.isNodeOccupied(node)) out_.appeared.push_back(key);
    }
    brick_ = &brick;
    visit(tree_.getRoot(), 0, false, 0, KeyBrick::kVoxels);
  }

 private:
  static constexpr unsigned kBrickDepthFromLeaf = 4;  // a brick is a subtree 4 levels above the leaves

  static bool any(const std::array<std::uint64_t, KeyBrick::kVoxels / 64>& words, int begin, int count) {
    if (count >= 64) {
      for (int w = begin >> 6; w < (begin + count) >> 6; ++w) {
        if (words[std::size_t(w)] != 0) return true;
      }
      return false;
    }
    const std::uint64_t mask = ((std::uint64_t{1} << count) - 1) << (begin & 63);
    return (words[std::size_t(begin >> 6)] & mask) != 0;
  }
  static bool all(const std::array<std::uint64_t, KeyBrick::kVoxels / 64>& words, int begin, int count) {
    if (count >= 64) {
      for (int w = begin >> 6; w < (begin + count) >> 6; ++w) {
        if (words[std::size_t(w)] != ~std::uint64_t{0}) return false;
      }
      return true;
    }
    const std::uint64_t mask = ((std::uint64_t{1} << count) - 1) << (begin & 63);
    return (words[std::size_t(begin >> 6)] & mask) == mask;
  }
  static int first_bit(const std::array<std::uint64_t, KeyBrick::kVoxels / 64>& words) {
    for (int w = 0;; ++w) {
      if (words[std::size_t(w)] != 0) return w * 64 + __builtin_ctzll(words[std::size_t(w)]);
    }
  }

  // Whether any voxel of the bit range would change a node holding `log_odds` (updateNode's early abort).
  bool needs_update(float log_odds, int begin, int count) const {
    return (log_odds < clamp_max_ && any(brick_->occupied, begin, count)) ||
           (log_odds > clamp_min_ && any(brick_->free, begin, count));
  }

  // Whether every voxel of the bit range gets the same update; `occupied` says which.
  bool uniform(int begin, int count, bool& occupied) const {
    if (all(brick_->free, begin, count)) {
      occupied = false;
      return true;
    }
    occupied = true;
    return all(brick_->occupied, begin, count);
  }

  // Updates `node`, a leaf or a node without children standing for every voxel of the bit range, all of
  // which get the same update, and records the voxels that flipped.
  void update_block(octomap::OcTreeNode* node, bool created, bool occupied, int begin, int count) {
    const bool was_occupied = !created && tree_.isNodeOccupied(node);
    tree_.updateNodeLogOdds(node, occupied ? hit_ : miss_);
    const bool now_occupied = tree_.isNodeOccupied(node);
    if (now_occupied == was_occupied) return;
    auto& flipped = now_occupied ? out_.appeared : out_.vanished;
    for (int i = begin; i < begin + count; ++i) flipped.push_back(brick_->key(i));
  }

  // `node` covers bit range [begin, begin + count) of the brick at tree depth `depth`; above the brick's
  // depth the range is the whole brick and only the path towards it is followed. `created`: the node is new
  // (log-odds 0, no children). Where a whole subtree gets one update and holds no finer nodes (a new node or
  // a pruned block), that one node is updated instead of creating or expanding its 8^k leaves, which would
  // end equal and be pruned again: each leaf below gets the value updateNode() would give it.
  void visit(octomap::OcTreeNode* node, unsigned depth, bool created, int begin, int count) {
    const unsigned brick_depth = depth_ - kBrickDepthFromLeaf;
    if (created || !tree_.nodeHasChildren(node)) {
      // A new node, an existing leaf or a pruned block: where updateNode()'s search() stops.
      if (!created && !needs_update(node->getLogOdds(), begin, count)) return;
      bool occupied = false;
      if (depth == depth_) {
        occupied = (brick_->occupied[std::size_t(begin >> 6)] >> (begin & 63)) & 1;
        update_block(node, created, occupied, begin, count);
        return;
      }
      if (depth >= brick_depth && uniform(begin, count, occupied)) {
        update_block(node, created, occupied, begin, count);
        return;
      }
      if (!created) tree_.expandNode(node);
    }
    if (depth < brick_depth) {
      visit_child(node, octomap::computeChildIdx(brick_->base, int(depth_ - 1 - depth)), depth, begin, count);
    } else {
      const int part = count / 8;
      for (unsigned pos = 0; pos < 8; ++pos) {
        const int child_begin = begin + int(pos) * part;
        if (any(brick_->occupied, child_begin, part) || any(brick_->free, child_begin, part)) {
          visit_child(node, pos, depth, child_begin, part);
        }
      }
    }
    node->updateOccupancyChildren();
    tree_.pruneNode(node);
  }

  void visit_child(octomap::OcTreeNode* node, unsigned pos, unsigned depth, int begin, int count) {
    bool created = false;
    if (!tree_.nodeChildExists(node, pos)) {
      tree_.createNodeChild(node, pos);
      created = true;
    }
    visit(tree_.getNodeChild(node, pos), depth + 1, created, begin, count);
  }

  octomap::OcTree& tree_;
  OccupancyUpdate& out_;
  const unsigned depth_;
  const float hit_, miss_, clamp_min_, clamp_max_;
  const KeyBrick* brick_ = nullptr;
};

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

OccupancyUpdate OccupancyMap::integrate(const Sweep& sweep) {
  const KeyUpdate keys = compute_key_update(sweep, *tree_, config_.max_range, config_.threads);
  OccupancyUpdate update;
  update.hit_voxels = keys.occupied_count;
  update.free_voxels = keys.free_count;
  BatchApplier applier(*tree_, update);
  for (const KeyBrick& brick : keys.bricks) applier.apply(brick);
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
  tree->readData(in);
  if (!in) throw Error("occupancy map: the saved map is truncated");
  tree_ = std::move(tree);
}

}  // namespace cellmap
