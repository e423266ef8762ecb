// SPDX-License-Identifier: Apache-2.0
#include "tree_agreement.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

constexpr double kResolution = 0.1;

// A tree with a 4 × 4 × 1 slab of free voxels and two occupied voxels on it (OctoMap's default model).
octomap::OcTree small_map() {
  octomap::OcTree tree(kResolution);
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 4; ++y)
      tree.updateNode(octomap::point3d(0.05f + 0.1f * x, 0.05f + 0.1f * y, 0.05f), false);
  tree.updateNode(octomap::point3d(0.05f, 0.05f, 0.15f), true);
  tree.updateNode(octomap::point3d(0.15f, 0.05f, 0.15f), true);
  return tree;
}

TEST(TreeAgreementTest, ATreeAgreesWithItsCopyVoxelForVoxel) {
  const octomap::OcTree a = small_map();
  const octomap::OcTree b = small_map();
  const TreeAgreement agreement = compare_trees(a, b);
  EXPECT_EQ(agreement.voxels, 18u);
  EXPECT_EQ(agreement.same, 18u);
  EXPECT_EQ(agreement.same_log_odds, 18u);
  EXPECT_EQ(agreement.occupied_a, 2u);
  EXPECT_EQ(agreement.occupied_b, 2u);
  EXPECT_EQ(agreement.occupied_both, 2u);
  EXPECT_DOUBLE_EQ(agreement.fraction(), 1.0);
}

TEST(TreeAgreementTest, CountsVoxelsKnownInOnlyOneTreeAndFlippedStates) {
  const octomap::OcTree a = small_map();
  octomap::OcTree b = small_map();
  b.updateNode(octomap::point3d(0.35f, 0.35f, 0.35f), true);                               // unknown in a
  for (int i = 0; i < 3; ++i) b.updateNode(octomap::point3d(0.15f, 0.05f, 0.15f), false);  // occupied → free
  const TreeAgreement agreement = compare_trees(a, b);
  EXPECT_EQ(agreement.voxels, 19u);
  EXPECT_EQ(agreement.same, 17u);
  EXPECT_EQ(agreement.same_log_odds, 17u);
  EXPECT_EQ(agreement.occupied_a, 2u);
  EXPECT_EQ(agreement.occupied_b, 2u);
  EXPECT_EQ(agreement.occupied_both, 1u);
  EXPECT_DOUBLE_EQ(agreement.fraction(), 17.0 / 19.0);
  const TreeAgreement reversed = compare_trees(b, a);
  EXPECT_EQ(reversed.same, agreement.same);
  EXPECT_EQ(reversed.occupied_a, agreement.occupied_b);
}

TEST(TreeAgreementTest, SameStateWithOtherLogOddsIsNotTheSameTree) {
  const octomap::OcTree a = small_map();
  octomap::OcTree b = small_map();
  b.updateNode(octomap::point3d(0.05f, 0.05f, 0.15f), true);  // a second hit: still occupied, more certain
  const TreeAgreement agreement = compare_trees(a, b);
  EXPECT_EQ(agreement.same, agreement.voxels);
  EXPECT_EQ(agreement.same_log_odds, agreement.voxels - 1);
}

TEST(TreeAgreementTest, PrunedNodesCountAsTheirLeaves) {
  // Eight sibling voxels with the same value are pruned into their parent; the copy built without pruning
  // holds eight leaves. Both are the same eight voxels.
  octomap::OcTree pruned(kResolution), unpruned(kResolution);
  const octomap::OcTreeKey origin = pruned.coordToKey(0.05, 0.05, 0.05);
  for (int i = 0; i < 8; ++i) {
    const octomap::OcTreeKey key(origin[0] - (origin[0] % 2) + (i & 1),
                                 origin[1] - (origin[1] % 2) + ((i >> 1) & 1),
                                 origin[2] - (origin[2] % 2) + ((i >> 2) & 1));
    pruned.updateNode(key, true);
    unpruned.updateNode(key, true, /*lazy_eval=*/true);
  }
  pruned.prune();
  ASSERT_LT(pruned.getNumLeafNodes(), unpruned.getNumLeafNodes());
  const TreeAgreement agreement = compare_trees(pruned, unpruned);
  EXPECT_EQ(agreement.voxels, 8u);
  EXPECT_EQ(agreement.same_log_odds, 8u);
  EXPECT_EQ(agreement.occupied_a, 8u);
}

TEST(TreeAgreementTest, RefusesTreesOfDifferentResolutions) {
  const octomap::OcTree a(0.1), b(0.05);
  EXPECT_THROW((void)compare_trees(a, b), Error);
}

}  // namespace
}  // namespace cellmap
