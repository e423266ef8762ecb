// SPDX-License-Identifier: Apache-2.0
#pragma once
// How closely two occupancy trees agree, voxel by voxel: used to check the fast sweep fusion against
// OctoMap's own OcTree::insertPointCloud.

#include <octomap/OcTree.h>

#include <cstddef>

namespace cellmap {

/// Counts over the leaf voxels known (free or occupied) in either tree.
struct TreeAgreement final {
  std::size_t voxels = 0;         ///< voxels known in at least one tree
  std::size_t same = 0;           ///< of those, voxels in the same state (unknown/free/occupied) in both
  std::size_t same_log_odds = 0;  ///< of those, voxels known in both with bit-identical log-odds
  std::size_t occupied_a = 0;     ///< occupied voxels of the first tree
  std::size_t occupied_b = 0;     ///< occupied voxels of the second tree
  std::size_t occupied_both = 0;  ///< voxels occupied in both

  /// same / voxels (1 for two empty trees).
  [[nodiscard]] double fraction() const { return voxels == 0 ? 1.0 : double(same) / double(voxels); }
};

/// Compares `a` and `b` at leaf resolution (pruned nodes are expanded); each tree's state uses its own
/// occupancy threshold. Two trees are the same voxel for voxel when same_log_odds == voxels. Both must have
/// the same resolution. Cost: O(known voxels) searches in each tree.
/// @throws Error if the resolutions differ.
[[nodiscard]] TreeAgreement compare_trees(const octomap::OcTree& a, const octomap::OcTree& b);

}  // namespace cellmap
