// SPDX-License-Identifier: Apache-2.0
#include "mesh_bvh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cellmap::sim {
namespace {

constexpr int kLeafSize = 4;

// Entry and exit distance of the ray through the box, with 1/d precomputed; false if it misses [0, t_max].
bool slabs(const Eigen::Vector3d& min, const Eigen::Vector3d& max, const Eigen::Vector3d& o,
           const Eigen::Vector3d& inv_d, double t_max, double& t_enter) {
  double t0 = 0.0, t1 = t_max;
  for (int i = 0; i < 3; ++i) {
    double a = (min[i] - o[i]) * inv_d[i], b = (max[i] - o[i]) * inv_d[i];
    if (std::isnan(a) || std::isnan(b)) {  // parallel to the slab with o on its plane: inside
      if (o[i] < min[i] || o[i] > max[i]) return false;
      continue;
    }
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a), t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  t_enter = t0;
  return true;
}

}  // namespace

MeshBvh::MeshBvh(const TriangleMesh& mesh) {
  mesh.validate("mesh");
  bounds_ = mesh.bounds();
  std::vector<Eigen::Vector3d> centroids;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const Eigen::Vector3d& b = mesh.vertices[t[1]];
    const Eigen::Vector3d& c = mesh.vertices[t[2]];
    triangles_.push_back({a, b - a, c - a});
    centroids.push_back((a + b + c) / 3.0);
  }
  std::vector<int> order(triangles_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  nodes_.reserve(2 * triangles_.size() / kLeafSize + 1);
  build(order, 0, static_cast<int>(order.size()), centroids);
  // Store triangles in leaf order so a leaf's triangles are contiguous.
  std::vector<Triangle> sorted;
  sorted.reserve(order.size());
  for (int i : order) sorted.push_back(triangles_[static_cast<std::size_t>(i)]);
  triangles_ = std::move(sorted);
}

int MeshBvh::build(std::vector<int>& order, int begin, int end,
                   const std::vector<Eigen::Vector3d>& centroids) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  node.max = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  Eigen::Vector3d c_min = node.min, c_max = node.max;
  for (int i = begin; i < end; ++i) {
    const Triangle& t = triangles_[static_cast<std::size_t>(order[i])];
    for (const Eigen::Vector3d& v : {t.v0, Eigen::Vector3d(t.v0 + t.e1), Eigen::Vector3d(t.v0 + t.e2)}) {
      node.min = node.min.cwiseMin(v), node.max = node.max.cwiseMax(v);
    }
    c_min = c_min.cwiseMin(centroids[order[i]]), c_max = c_max.cwiseMax(centroids[order[i]]);
  }
  if (end - begin <= kLeafSize) {
    node.first = begin, node.count = end - begin;
    nodes_[index] = node;
    return index;
  }
  int axis = 0;
  (c_max - c_min).maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end,
                   [&](int a, int b) { return centroids[a][axis] < centroids[b][axis]; });
  // Depth first: the left child is the next node, the inner node keeps the right child's index.
  build(order, begin, middle, centroids);
  node.first = build(order, middle, end, centroids);
  node.count = 0;
  nodes_[index] = node;
  return index;
}

std::optional<double> MeshBvh::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                         double t_max) const {
  const Eigen::Vector3d inv_d = d.cwiseInverse();
  double best = t_max;
  bool hit = false;
  int stack[64];  // a median split keeps the depth near log2(triangles / 4)
  int top = 0;
  double t_enter = 0;
  if (!slabs(nodes_[0].min, nodes_[0].max, o, inv_d, best, t_enter)) return std::nullopt;
  stack[top++] = 0;
  while (top > 0) {
    const int index = stack[--top];
    const Node& node = nodes_[static_cast<std::size_t>(index)];
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        // Möller–Trumbore, both sides.
        const Triangle& t = triangles_[static_cast<std::size_t>(i)];
        const Eigen::Vector3d p = d.cross(t.e2);
        const double det = t.e1.dot(p);
        if (std::abs(det) < 1e-15) continue;
        const double inv_det = 1.0 / det;
        const Eigen::Vector3d s = o - t.v0;
        const double u = s.dot(p) * inv_det;
        if (u < 0 || u > 1) continue;
        const Eigen::Vector3d q = s.cross(t.e1);
        const double v = d.dot(q) * inv_det;
        if (v < 0 || u + v > 1) continue;
        const double distance = t.e2.dot(q) * inv_det;
        if (distance >= 0 && distance <= best) best = distance, hit = true;
      }
      continue;
    }
    const int children[2] = {index + 1, node.first};
    double enter[2];
    bool meets[2];
    for (int c = 0; c < 2; ++c) {
      const Node& child = nodes_[static_cast<std::size_t>(children[c])];
      meets[c] = slabs(child.min, child.max, o, inv_d, best, enter[c]);
    }
    // Push the farther child first so the nearer one is searched first and tightens `best`.
    const int near = meets[0] && meets[1] ? (enter[0] <= enter[1] ? 0 : 1) : (meets[0] ? 0 : 1);
    if (meets[1 - near]) stack[top++] = children[1 - near];
    if (meets[near]) stack[top++] = children[near];
  }
  if (!hit) return std::nullopt;
  return best;
}

}  // namespace cellmap::sim
