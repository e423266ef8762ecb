// SPDX-License-Identifier: Apache-2.0
#include "coverage.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <tuple>
#include <unordered_map>

#include "cellmap/common/parallel.hpp"

namespace cellmap {
namespace {

constexpr double kTolerance = 1e-7;  // metres; the grown boxes hold their cubes to rounding

// Half extents, along a box's own axes, of a cube of edge `edge`: edge / 2 · ‖axis‖₁.
Eigen::Vector3d cube_half(const Eigen::Matrix3d& R, double edge) {
  return 0.5 * edge * R.cwiseAbs().colwise().sum().transpose();
}

// The smallest box with `box`'s axes holding `box` and the cube around `centre_C`.
Box grown_to_hold(const Box& box, const Eigen::Vector3d& centre_C, double edge) {
  const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
  const Eigen::Vector3d p = R.transpose() * (centre_C - box.center);
  const Eigen::Vector3d w = cube_half(R, edge);
  const Eigen::Vector3d lower = (-box.half_extents).cwiseMin(p - w);
  const Eigen::Vector3d upper = box.half_extents.cwiseMax(p + w);
  Box grown = box;
  grown.half_extents = 0.5 * (upper - lower);
  grown.center = box.center + R * (0.5 * (upper + lower));
  grown.points += 1;
  return grown;
}

// Index of the box of `boxes` that takes the cube around `centre_C` with the least growth, -1 if none may:
// the cube must lie within `reach` of the box as it was before the pass (`before`, same order), and the box's
// growth in the pass stay at most max_growth of that volume.
int cheapest_growth(const std::vector<Box>& boxes, const std::vector<Box>& before,
                    const Eigen::Vector3d& centre_C, const CoverParams& o) {
  int best = -1;
  double best_added = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < before.size(); ++i) {
    Box reachable = before[i];
    reachable.half_extents.array() += o.reach;
    if (!holds_cube(reachable, centre_C, o.voxel)) continue;
    const Box grown = grown_to_hold(boxes[i], centre_C, o.voxel);
    const double added = grown.volume() - boxes[i].volume();
    if (grown.volume() - before[i].volume() <= o.max_growth * before[i].volume() && added < best_added) {
      best = static_cast<int>(i);
      best_added = added;
    }
  }
  return best;
}

// Grows `boxes` (`before`: as they were before the pass, same order) to take every voxel of `group`, each by
// the box that grows least for it, and lists the boxes grown in `grown`. A group that some voxel of lies
// beyond every box's reach is an object, or part of one, rather than a surface filling in: it leaves the
// boxes as they were and returns false, so that it gets a box of its own instead of hiding in an older one.
bool take_group(std::vector<Box>& boxes, const std::vector<Box>& before,
                const std::vector<Eigen::Vector3d>& group, const CoverParams& options,
                std::vector<std::size_t>& grown) {
  std::vector<Box> taking = boxes;
  for (const Eigen::Vector3d& c : group) {
    const int taker = cheapest_growth(taking, before, c, options);
    if (taker < 0) return false;
    taking[static_cast<std::size_t>(taker)] =
        grown_to_hold(taking[static_cast<std::size_t>(taker)], c, options.voxel);
    grown.push_back(static_cast<std::size_t>(taker));
  }
  std::sort(grown.begin(), grown.end());
  grown.erase(std::unique(grown.begin(), grown.end()), grown.end());
  boxes = std::move(taking);
  return true;
}

// A new box holding every voxel of `group` whole.
Box box_of_group(const std::vector<Eigen::Vector3d>& group, const CoverParams& options) {
  Box box = fit_box(group, options.kind, options.voxel);
  for (const Eigen::Vector3d& c : group) {
    if (!holds_cube(box, c, options.voxel)) box = grown_to_hold(box, c, options.voxel);
  }
  return box;
}

// Records box `box` (already in reconciled.boxes) as changed: added stays added, else modified.
void record_grown(Reconciled& reconciled, const Box& box) {
  for (std::vector<Box>* list : {&reconciled.added, &reconciled.modified}) {
    const auto it = std::find_if(list->begin(), list->end(), [&](const Box& b) { return b.id == box.id; });
    if (it != list->end()) {
      *it = box;
      return;
    }
  }
  reconciled.modified.push_back(box);
}

}  // namespace

std::vector<std::vector<Eigen::Vector3d>> connected_groups(const std::vector<Eigen::Vector3d>& centres_C,
                                                           double voxel) {
  const auto cell_of = [&](const Eigen::Vector3d& c) {
    return Eigen::Vector3i((c / voxel).array().floor().cast<int>());
  };
  const auto hash = [](const Eigen::Vector3i& v) {
    return (static_cast<std::size_t>(v.x()) * 73856093u) ^ (static_cast<std::size_t>(v.y()) * 19349663u) ^
           (static_cast<std::size_t>(v.z()) * 83492791u);
  };
  std::unordered_map<Eigen::Vector3i, int, decltype(hash)> index(centres_C.size(), hash);
  for (std::size_t i = 0; i < centres_C.size(); ++i)
    index.emplace(cell_of(centres_C[i]), static_cast<int>(i));
  std::vector<int> group(centres_C.size(), -1);
  std::vector<std::vector<Eigen::Vector3d>> groups;
  for (std::size_t seed = 0; seed < centres_C.size(); ++seed) {
    if (group[seed] >= 0) continue;
    const int g = static_cast<int>(groups.size());
    groups.emplace_back();
    std::vector<int> stack{static_cast<int>(seed)};
    group[seed] = g;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      groups[g].push_back(centres_C[i]);
      const Eigen::Vector3i at = cell_of(centres_C[i]);
      for (int n = 0; n < 27; ++n) {
        const auto it = index.find(at + Eigen::Vector3i(n % 3 - 1, n / 3 % 3 - 1, n / 9 - 1));
        if (it == index.end() || group[it->second] >= 0) continue;
        group[it->second] = g;
        stack.push_back(it->second);
      }
    }
  }
  return groups;
}

bool holds_cube(const Box& box, const Eigen::Vector3d& centre_C, double edge) {
  const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
  const Eigen::Vector3d p = R.transpose() * (centre_C - box.center);
  return (p.cwiseAbs() + cube_half(R, edge) - box.half_extents).maxCoeff() <= kTolerance;
}

CubeHolders::CubeHolders(const std::vector<Box>& boxes, double edge) {
  boxes_.reserve(boxes.size());
  for (const Box& box : boxes) {
    const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
    boxes_.push_back({bounds_of(box), R, box.center, box.half_extents, cube_half(R, edge)});
  }
}

// holds_cube's test with the box's part precomputed; a held cube's centre lies inside the box by half an
// edge, so the bounds never turn a held cube away.
bool CubeHolders::holds(const Held& box, const Eigen::Vector3d& centre_C) {
  if (!box.bounds.contains(centre_C)) return false;
  const Eigen::Vector3d p = box.rotation.transpose() * (centre_C - box.center);
  return (p.cwiseAbs() + box.cube_half - box.half_extents).maxCoeff() <= kTolerance;
}

bool CubeHolders::hold(const Eigen::Vector3d& centre_C) {
  if (boxes_.empty()) return false;
  if (holds(boxes_[last_], centre_C)) return true;
  for (std::size_t i = 0; i < boxes_.size(); ++i) {
    if (i != last_ && holds(boxes_[i], centre_C)) {
      last_ = i;
      return true;
    }
  }
  return false;
}

OccupiedVoxels::OccupiedVoxels(const OccupancyMap& map)
    : keys_(map.occupied_keys()), set_(keys_.begin(), keys_.end()) {}

void OccupiedVoxels::apply(const OccupancyUpdate& update) {
  if (update.appeared.empty() && update.vanished.empty()) return;
  const auto zyx = [](const octomap::OcTreeKey& a, const octomap::OcTreeKey& b) {
    return std::tie(a[2], a[1], a[0]) < std::tie(b[2], b[1], b[0]);
  };
  std::vector<octomap::OcTreeKey> kept;
  kept.reserve(keys_.size());
  std::set_difference(keys_.begin(), keys_.end(), update.vanished.begin(), update.vanished.end(),
                      std::back_inserter(kept), zyx);
  keys_.clear();
  std::merge(kept.begin(), kept.end(), update.appeared.begin(), update.appeared.end(),
             std::back_inserter(keys_), zyx);
  for (const octomap::OcTreeKey& key : update.vanished) set_.erase(key);
  set_.insert(update.appeared.begin(), update.appeared.end());
}

bool OccupiedVoxels::in_group_of(const octomap::OcTreeKey& seed, int size) const {
  if (set_.count(seed) == 0) return false;
  std::vector<octomap::OcTreeKey> found{seed};
  for (std::size_t next = 0; next < found.size() && static_cast<int>(found.size()) < size; ++next) {
    for (int n = 0; n < 27 && static_cast<int>(found.size()) < size; ++n) {
      octomap::OcTreeKey key = found[next];
      key[0] = static_cast<octomap::key_type>(key[0] + n % 3 - 1);
      key[1] = static_cast<octomap::key_type>(key[1] + n / 3 % 3 - 1);
      key[2] = static_cast<octomap::key_type>(key[2] + n / 9 - 1);
      if (set_.count(key) > 0 && std::find(found.begin(), found.end(), key) == found.end()) {
        found.push_back(key);
      }
    }
  }
  return static_cast<int>(found.size()) >= size;
}

bool OccupiedVoxels::in_group_of(const OccupancyMap& map, const Eigen::Vector3d& centre_C, int size) const {
  return in_group_of(map.tree().coordToKey(octomap::point3d(static_cast<float>(centre_C.x()),
                                                            static_cast<float>(centre_C.y()),
                                                            static_cast<float>(centre_C.z()))),
                     size);
}

std::vector<Eigen::Vector3d> voxels_outside(const OccupancyMap& map, const OccupiedVoxels& voxels,
                                            const std::vector<Box>& boxes, int min_group, int threads) {
  constexpr std::size_t kMinVoxelsPerThread = 4096;  // fewer go faster on one thread than others start
  const std::vector<octomap::OcTreeKey>& keys = voxels.keys();
  const int chunks =
      int(std::clamp<std::size_t>(keys.size() / kMinVoxelsPerThread, 1, std::size_t(std::max(threads, 1))));
  // Each thread a contiguous run of the keys, so that the runs joined keep the keys' order.
  std::vector<std::vector<Eigen::Vector3d>> outside(static_cast<std::size_t>(chunks));
  parallel_for(chunks, chunks, [&](int chunk) {
    CubeHolders holders(boxes, map.config().resolution);
    const std::size_t end = keys.size() * std::size_t(chunk + 1) / std::size_t(chunks);
    for (std::size_t k = keys.size() * std::size_t(chunk) / std::size_t(chunks); k < end; ++k) {
      const Eigen::Vector3d c = map.centre(keys[k]);
      if (!holders.hold(c) && voxels.in_group_of(keys[k], min_group))
        outside[std::size_t(chunk)].push_back(c);
    }
  });
  for (std::size_t t = 1; t < outside.size(); ++t)
    outside[0].insert(outside[0].end(), outside[t].begin(), outside[t].end());
  return std::move(outside[0]);
}

void cover(Reconciled& reconciled, const std::vector<Eigen::Vector3d>& centres_C,
           const CoverParams& options) {
  std::vector<Box>& boxes = reconciled.boxes;
  const std::vector<Box> before = boxes;
  std::vector<Eigen::Vector3d> outside;
  for (const Eigen::Vector3d& c : centres_C) {
    const auto holds = [&](const Box& box) { return holds_cube(box, c, options.voxel); };
    if (std::none_of(boxes.begin(), boxes.end(), holds)) outside.push_back(c);
  }
  std::vector<Box> fresh;
  for (const std::vector<Eigen::Vector3d>& group : connected_groups(outside, options.voxel)) {
    std::vector<std::size_t> grown;
    if (take_group(boxes, before, group, options, grown)) {
      for (std::size_t i : grown) record_grown(reconciled, boxes[i]);
    } else {
      fresh.push_back(box_of_group(group, options));
      fresh.back().id = reconciled.next_id++;
    }
  }
  for (const Box& box : fresh) {
    boxes.push_back(box);
    reconciled.added.push_back(box);
  }
  const auto by_id = [](const Box& a, const Box& b) { return a.id < b.id; };
  std::sort(boxes.begin(), boxes.end(), by_id);
  std::sort(reconciled.added.begin(), reconciled.added.end(), by_id);
  std::sort(reconciled.modified.begin(), reconciled.modified.end(), by_id);
}

}  // namespace cellmap
