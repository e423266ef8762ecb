#include <gtest/gtest.h>

#include <set>
#include <sstream>

#include "cellmap/common/error.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "tree_agreement.hpp"

namespace cellmap {
namespace {

// One scan from above onto a 10 cm × 10 cm patch at z = 0 (2 cm voxels: 5 × 5 occupied voxels).
Sweep patch_sweep() {
  Scan scan;
  scan.origin_C = {0.05, 0.05, 1.0};
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j)
      scan.points_C.push_back(pcl::PointXYZ(0.01f + 0.02f * i, 0.01f + 0.02f * j, 0.001f));
  }
  Sweep sweep;
  sweep.scans.push_back(scan);
  return sweep;
}

TEST(OccupancyMapStateTest, OccupiedCentresInsideRegionsOnly) {
  OccupancyMap map;
  (void)map.integrate(patch_sweep());
  EXPECT_EQ(map.occupied_centres({Region{{-1, -1, -1}, {1, 1, 1}}}).size(), 25u);
  // The region covers the voxel centres with x < 0.04: columns x = 0.01 and 0.03.
  const auto some = map.occupied_centres({Region{{0.0, 0.0, -0.1}, {0.04, 1, 0.1}}});
  EXPECT_EQ(some.size(), 10u);
  for (const auto& c : some) EXPECT_LT(c.x(), 0.04);
  // Two overlapping regions count each voxel once.
  EXPECT_EQ(map.occupied_centres({Region{{-1, -1, -1}, {1, 1, 1}}, Region{{0, 0, -1}, {1, 1, 1}}}).size(),
            25u);
  EXPECT_TRUE(map.occupied_centres({Region{{2, 2, 2}, {3, 3, 3}}}).empty());
}

TEST(OccupancyMapStateTest, WriteReadKeepsEveryVoxelAndItsEvidence) {
  // Two sweeps, the second from another viewpoint: voxels hold different log-odds (hit twice, hit once and
  // crossed, crossed once or twice), and every one of them must come back bit for bit.
  OccupancyMap map;
  (void)map.integrate(patch_sweep());
  Sweep second = patch_sweep();
  second.scans.front().origin_C = {0.3, 0.05, 0.8};
  (void)map.integrate(second);
  std::stringstream saved;
  map.write(saved);
  OccupancyMap restored;
  restored.read(saved);
  EXPECT_EQ(restored.occupied_keys(), map.occupied_keys());
  EXPECT_EQ(restored.tree().size(), map.tree().size());
  const TreeAgreement agreement = compare_trees(restored.tree(), map.tree());
  EXPECT_GT(agreement.voxels, 800u);  // the patch and the rays to it: 849
  std::set<float> evidence;
  for (auto it = map.tree().begin_leafs(); it != map.tree().end_leafs(); ++it)
    evidence.insert(it->getLogOdds());
  EXPECT_GE(evidence.size(), 3u) << "every voxel holds the same evidence: the test would prove little";
  EXPECT_EQ(agreement.same_log_odds, agreement.voxels);
}

TEST(OccupancyMapStateTest, ReadRejectsOtherResolutionAndGarbage) {
  OccupancyMap map;
  (void)map.integrate(patch_sweep());
  std::stringstream saved;
  map.write(saved);
  OccupancyConfig coarse;
  coarse.resolution = 0.05;
  OccupancyMap other(coarse);
  EXPECT_THROW(other.read(saved), Error);
  std::stringstream garbage("not a map\n");
  EXPECT_THROW(other.read(garbage), Error);
  std::stringstream truncated(saved.str().substr(0, saved.str().size() / 2));
  OccupancyMap again;
  EXPECT_THROW(again.read(truncated), Error);
}

}  // namespace
}  // namespace cellmap
