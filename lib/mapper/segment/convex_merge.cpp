// SPDX-License-Identifier: Apache-2.0
#include "cellmap/segment/convex_merge.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <unordered_map>

#include "cellmap/common/error.hpp"
#include "cellmap/preprocess/point_search.hpp"

namespace cellmap {
namespace {

struct Patch {
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  int size = 0;
};

class UnionFind {
 public:
  explicit UnionFind(int n) : parent_(static_cast<std::size_t>(n)) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  int find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(int a, int b) { parent_[find(a)] = find(b); }

 private:
  std::vector<int> parent_;
};

// Boundary point pairs (closer than the gap) per adjacent segment pair, keyed (smaller label << 32) | larger.
using Boundaries = std::unordered_map<std::uint64_t, std::vector<std::pair<int, int>>>;

Boundaries boundaries_of(const Neighbourhoods& nb, const Segments& segments, double gap) {
  const float max_sq_gap = static_cast<float>(gap * gap);
  Boundaries boundaries;
  for (int i = 0; i < nb.size(); ++i) {
    const int a = segments.label[i];
    if (a < 0) continue;
    for (int j = 0; j < nb.k; ++j) {
      const int other = nb.neighbour(i, j);
      if (other < 0 || nb.sq_distance(i, j) > max_sq_gap) break;
      const int b = segments.label[other];
      if (b <= a) continue;  // each unordered pair once, from its smaller label's side
      boundaries[(static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b)].emplace_back(i,
                                                                                                     other);
    }
  }
  return boundaries;
}

// The patches of one segment around boundary points: centroid and mean normal within the patch radius.
class PatchFinder {
 public:
  PatchFinder(const Cloud& cloud, const Neighbourhoods& nb, const Segments& segments, double radius)
      : cloud_(cloud), nb_(nb), segments_(segments), radius_(radius), tree_(cloud) {}
  Patch at(int centre, int segment) {
    Patch p;
    tree_.within(cloud_[centre], radius_, false, near_, near_sq_);
    for (int q : near_) {
      if (segments_.label[q] != segment) continue;
      p.centroid += cloud_[q].getVector3fMap();
      p.normal += nb_.normals[q];
      ++p.size;
    }
    if (p.size > 0) p.centroid /= static_cast<float>(p.size);
    if (p.normal.norm() > 0.0f) p.normal.normalize();
    return p;
  }

 private:
  const Cloud& cloud_;
  const Neighbourhoods& nb_;
  const Segments& segments_;
  double radius_;
  PointSearch tree_;
  pcl::Indices near_;
  std::vector<float> near_sq_;
};

// How convex the boundary between segments a and b is: per place v = (n_s − n_t)·d̂ with
// d̂ = (x_s − x_t)/|x_s − x_t|, v >= 0 is LCCP's convex case, v < 0 concave, and a concave bend by an angle β
// gives v ≈ −2 sin(β/2). The median over the sampled places decides; nullopt if no place had patches.
std::optional<float> convexity(const std::vector<std::pair<int, int>>& pairs, int a, int b,
                               const ConvexMergeParams& params, PatchFinder& patches) {
  const int samples = std::min<int>(params.samples_per_boundary, static_cast<int>(pairs.size()));
  std::vector<float> v;
  v.reserve(static_cast<std::size_t>(samples));
  for (int s = 0; s < samples; ++s) {
    const auto [i, j] = pairs[static_cast<std::size_t>(s) * pairs.size() / samples];
    const Patch ps = patches.at(i, a);
    const Patch pt = patches.at(j, b);
    if (ps.size < 3 || pt.size < 3) continue;
    const Eigen::Vector3f d = ps.centroid - pt.centroid;
    if (d.norm() <= 0.0f) continue;
    v.push_back((ps.normal - pt.normal).dot(d.normalized()));
  }
  if (v.empty()) return std::nullopt;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

struct Edge {
  float score;
  int a, b;
};

// Most convex first; a merge that would join two segments with a concave boundary between them is refused,
// so a small fragment convex to both an object and the table cannot chain them together.
void merge_convex_edges(std::vector<Edge>& convex, const std::vector<Edge>& concave, UnionFind& sets,
                        MergeStats& stats) {
  std::sort(convex.begin(), convex.end(), [](const Edge& x, const Edge& y) { return x.score > y.score; });
  for (const Edge& edge : convex) {
    const int ra = sets.find(edge.a), rb = sets.find(edge.b);
    if (ra == rb) continue;
    const bool conflict = std::any_of(concave.begin(), concave.end(), [&](const Edge& c) {
      const int ca = sets.find(c.a), cb = sets.find(c.b);
      return (ca == ra && cb == rb) || (ca == rb && cb == ra);
    });
    if (conflict) continue;
    sets.unite(ra, rb);
    ++stats.convex_pairs;
  }
}

}  // namespace

Segments merge_convex(const Cloud& cloud, const Neighbourhoods& nb, const Segments& segments,
                      const ConvexMergeParams& params, MergeStats* stats) {
  if (segments.label.size() != cloud.size() || nb.normals.size() != cloud.size()) {
    throw Error("merge_convex: cloud, neighbourhoods and labels differ in size");
  }
  PatchFinder patches(cloud, nb, segments, params.patch_radius);
  const float concave_limit = static_cast<float>(-2.0 * std::sin(0.5 * params.concavity_tolerance));
  MergeStats local;
  std::vector<Edge> convex, concave;
  for (const auto& [key, pairs] : boundaries_of(nb, segments, params.gap)) {
    if (static_cast<int>(pairs.size()) < params.min_boundary_points) continue;
    ++local.adjacent_pairs;
    const int a = static_cast<int>(key >> 32);
    const int b = static_cast<int>(key & 0xffffffffu);
    const std::optional<float> score = convexity(pairs, a, b, params, patches);
    if (score) (*score >= concave_limit ? convex : concave).push_back({*score, a, b});
  }
  UnionFind sets(segments.count);
  merge_convex_edges(convex, concave, sets, local);
  if (stats) *stats = local;

  std::vector<int> merged(segments.label.size(), -1);
  for (std::size_t i = 0; i < merged.size(); ++i) {
    if (segments.label[i] >= 0) merged[i] = sets.find(segments.label[i]);
  }
  return compact_segments(merged);
}

}  // namespace cellmap
