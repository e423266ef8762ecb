// SPDX-License-Identifier: Apache-2.0
#include "tree_agreement.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cellmap/common/error.hpp"
#include "key_update.hpp"

namespace cellmap {
namespace {

// Appends the packed leaf keys of every known voxel of `tree`, expanding pruned leaves.
void append_known(const octomap::OcTree& tree, std::vector<std::uint64_t>& out) {
  const unsigned depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (it.getDepth() == depth) {
      out.push_back(pack_key(it.getKey()));
      continue;
    }
    const int span = 1 << (depth - it.getDepth());
    const octomap::OcTreeKey first = it.getIndexKey();
    for (int z = 0; z < span; ++z)
      for (int y = 0; y < span; ++y)
        for (int x = 0; x < span; ++x)
          out.push_back(pack_key(octomap::OcTreeKey(first[0] + x, first[1] + y, first[2] + z)));
  }
}

// 0 unknown, 1 free, 2 occupied.
int state(const octomap::OcTree& tree, const octomap::OcTreeNode* node) {
  if (node == nullptr) return 0;
  return tree.isNodeOccupied(node) ? 2 : 1;
}

}  // namespace

TreeAgreement compare_trees(const octomap::OcTree& a, const octomap::OcTree& b) {
  if (a.getResolution() != b.getResolution())
    throw Error("compare_trees: the trees have different resolutions");
  std::vector<std::uint64_t> keys;
  append_known(a, keys);
  append_known(b, keys);
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());

  TreeAgreement result;
  result.voxels = keys.size();
  for (const std::uint64_t p : keys) {
    const octomap::OcTreeKey key(static_cast<std::uint16_t>(p & 0xffff),
                                 static_cast<std::uint16_t>((p >> 16) & 0xffff),
                                 static_cast<std::uint16_t>(p >> 32));
    const octomap::OcTreeNode* na = a.search(key);
    const octomap::OcTreeNode* nb = b.search(key);
    const int sa = state(a, na);
    const int sb = state(b, nb);
    if (sa == sb) ++result.same;
    if (na != nullptr && nb != nullptr && na->getLogOdds() == nb->getLogOdds()) ++result.same_log_odds;
    if (sa == 2) ++result.occupied_a;
    if (sb == 2) ++result.occupied_b;
    if (sa == 2 && sb == 2) ++result.occupied_both;
  }
  return result;
}

}  // namespace cellmap
