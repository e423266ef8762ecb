// SPDX-License-Identifier: Apache-2.0
#include "cellmap/collision/box_tree.hpp"

#include <algorithm>
#include <numeric>

namespace cellmap::collision {

BoxTree::BoxTree(const std::vector<Obb>& boxes) : count_(boxes.size()) {
  lo_.reserve(boxes.size());
  hi_.reserve(boxes.size());
  for (const Obb& box : boxes) {
    const Eigen::Vector3d extent = box.aabb_half_extents();
    lo_.push_back(box.center - extent);
    hi_.push_back(box.center + extent);
  }
  order_.resize(boxes.size());
  std::iota(order_.begin(), order_.end(), 0);
  if (!boxes.empty()) {
    nodes_.reserve(2 * boxes.size());
    build(0, static_cast<int>(boxes.size()), lo_, hi_);
  }
}

// Builds the subtree over order_[begin, end); returns its node index.
int BoxTree::build(int begin, int end, const std::vector<Eigen::Vector3d>& lo,
                   const std::vector<Eigen::Vector3d>& hi) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d node_lo = lo[order_[begin]];
  Eigen::Vector3d node_hi = hi[order_[begin]];
  for (int i = begin + 1; i < end; ++i) {
    node_lo = node_lo.cwiseMin(lo[order_[i]]);
    node_hi = node_hi.cwiseMax(hi[order_[i]]);
  }
  nodes_[index].lo = node_lo;
  nodes_[index].hi = node_hi;
  if (end - begin <= 4) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  (node_hi - node_lo).maxCoeff(&axis);
  const int middle = (begin + end) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](int a, int b) { return lo[a][axis] + hi[a][axis] < lo[b][axis] + hi[b][axis]; });
  const int left = build(begin, middle, lo, hi);
  const int right = build(middle, end, lo, hi);
  nodes_[index].first = left;
  nodes_[index].right = right;
  nodes_[index].count = 0;
  return index;
}

void BoxTree::query(const Eigen::Vector3d& center, const Eigen::Vector3d& half_extents, double cutoff,
                    std::vector<int>* out) const {
  if (nodes_.empty()) return;
  const Eigen::Vector3d lo = center - half_extents;
  const Eigen::Vector3d hi = center + half_extents;
  const double cutoff2 = cutoff * cutoff;
  const auto gap2 = [&](const Eigen::Vector3d& node_lo, const Eigen::Vector3d& node_hi) {
    return (node_lo - hi).cwiseMax(lo - node_hi).cwiseMax(0.0).squaredNorm();
  };
  // Depth is at most log2(n / 4) + 1 thanks to the median split; 64 levels cover any vector size.
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    const double node_gap2 = gap2(node.lo, node.hi);
    if (node_gap2 > 0.0 && node_gap2 >= cutoff2) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const int box = order_[i];
        const double box_gap2 = gap2(lo_[box], hi_[box]);
        if (box_gap2 == 0.0 || box_gap2 < cutoff2) out->push_back(box);
      }
    } else {
      stack[top++] = node.first;
      stack[top++] = node.right;
    }
  }
}

}  // namespace cellmap::collision
