// SPDX-License-Identifier: Apache-2.0
// Equation and algorithm numbers are those of K. Zauner, J. El Dib, H. Gattringer, A. Müller,
// "Workspace Registration and Collision Detection for Industrial Robotics Applications", AIRoV 2024.
#include "cellmap/segment/region_growing.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "cellmap/common/error.hpp"
#include "cellmap/preprocess/point_search.hpp"

namespace cellmap {

Segments compact_segments(const std::vector<int>& label, const std::vector<bool>& drop) {
  Segments result;
  result.label.assign(label.size(), -1);
  std::unordered_map<int, int> renumber;
  for (std::size_t i = 0; i < label.size(); ++i) {
    const int old = label[i];
    if (old < 0 || (static_cast<std::size_t>(old) < drop.size() && drop[static_cast<std::size_t>(old)]))
      continue;
    const auto [it, inserted] = renumber.emplace(old, result.count);
    if (inserted) ++result.count;
    result.label[i] = it->second;
  }
  return result;
}

Segments grow_regions(const Neighbourhoods& nb, const RegionGrowingParams& params) {
  if (nb.normals.size() != static_cast<std::size_t>(nb.size()))
    throw Error("region growing: normals are missing");
  if (!(params.gap > 0.0)) throw Error("region growing: gap must be > 0");
  if (!(params.max_angle >= 0.0)) throw Error("region growing: max_angle must be >= 0");
  const int n = nb.size();
  const float max_sq_gap = static_cast<float>(params.gap * params.gap);
  const float min_cos = static_cast<float>(std::cos(params.max_angle));
  const float max_curvature = static_cast<float>(params.max_curvature);

  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return nb.curvature[a] < nb.curvature[b]; });

  std::vector<int> label(n, -1);
  std::vector<int> region_size;
  std::vector<int> queue;
  for (int seed : order) {
    if (label[seed] >= 0) continue;
    const int region = static_cast<int>(region_size.size());
    label[seed] = region;
    int size = 1;
    queue.assign(1, seed);
    while (!queue.empty()) {
      const int i = queue.back();
      queue.pop_back();
      for (int j = 0; j < nb.k; ++j) {
        const int other = nb.neighbour(i, j);
        // Neighbours come nearest first: the first one beyond the gap ends the list (eq. 3).
        if (other < 0 || nb.sq_distance(i, j) > max_sq_gap) break;
        if (label[other] >= 0) continue;
        if (nb.normals[i].dot(nb.normals[other]) < min_cos) continue;  // eq. 5
        label[other] = region;
        ++size;
        if (nb.curvature[other] <= max_curvature) queue.push_back(other);  // eq. 4
      }
    }
    region_size.push_back(size);
  }
  std::vector<bool> drop(region_size.size());
  for (std::size_t r = 0; r < region_size.size(); ++r) drop[r] = region_size[r] < params.min_cluster_size;
  return compact_segments(label, drop);
}

namespace {

// Attaches leftovers in waves: each takes the segment of its nearest labelled k-neighbour within the gap,
// with labels read from the previous wave (so the result does not depend on the order of the points). A band
// of leftovers between two segments is thus shared out by distance, never bridged. Returns the rest.
std::vector<int> attach_in_waves(std::vector<int> still, const Neighbourhoods& nb, Segments& segments,
                                 float max_sq_gap, LeftoverStats& stats) {
  std::vector<std::pair<int, int>> assigned;
  while (!still.empty()) {
    assigned.clear();
    std::vector<int> next;
    for (int i : still) {
      int found = -1;
      for (int j = 0; j < nb.k; ++j) {
        const int other = nb.neighbour(i, j);
        if (other < 0 || nb.sq_distance(i, j) > max_sq_gap) break;
        if (segments.label[other] >= 0) {
          found = segments.label[other];
          break;
        }
      }
      if (found >= 0) {
        assigned.emplace_back(i, found);
      } else {
        next.push_back(i);
      }
    }
    if (assigned.empty()) break;
    for (const auto& [i, label] : assigned) segments.label[i] = label;
    stats.attached += assigned.size();
    still = std::move(next);
  }
  return still;
}

// Euclidean clusters of `still` at the gap: those of at least min_points become segments of their own.
void cluster_the_rest(const Cloud& cloud, const std::vector<int>& still, Segments& segments, double gap,
                      int min_points, LeftoverStats& stats) {
  const PointSearch tree(cloud, still);
  std::unordered_map<int, bool> visited;
  for (int i : still) visited[i] = false;
  pcl::Indices near;
  std::vector<float> near_sq;
  for (int start : still) {
    if (visited[start]) continue;
    std::vector<int> group{start};
    visited[start] = true;
    for (std::size_t g = 0; g < group.size(); ++g) {
      tree.within(cloud[group[g]], gap, false, near, near_sq);
      for (int other : near) {
        if (!visited[other]) {
          visited[other] = true;
          group.push_back(other);
        }
      }
    }
    if (static_cast<int>(group.size()) < min_points) {
      stats.isolated += group.size();
      continue;
    }
    for (int i : group) segments.label[i] = segments.count;
    ++segments.count;
    ++stats.own_segments;
    stats.in_own_segments += group.size();
  }
}

}  // namespace

LeftoverStats cover_leftovers(const Cloud& cloud, const Neighbourhoods& nb, Segments& segments, double gap,
                              int min_points) {
  if (segments.label.size() != cloud.size() || static_cast<std::size_t>(nb.size()) != cloud.size()) {
    throw Error("cover_leftovers: labels, neighbourhoods and cloud differ in size");
  }
  if (!(gap > 0.0)) throw Error("cover_leftovers: gap must be > 0");
  LeftoverStats stats;
  std::vector<int> leftovers;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (segments.label[i] < 0) leftovers.push_back(static_cast<int>(i));
  }
  const std::vector<int> still =
      attach_in_waves(std::move(leftovers), nb, segments, static_cast<float>(gap * gap), stats);
  if (!still.empty()) cluster_the_rest(cloud, still, segments, gap, min_points, stats);
  return stats;
}

}  // namespace cellmap
