// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>
#include <string>

#include "cellmap/common/error.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "support/test_support.hpp"
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

// A saved map written by hand: write()'s header, then `nodes` (OctoMap's node data).
std::string saved_map(const std::string& nodes) {
  std::ostringstream header;
  OccupancyMap().write(header);  // an empty map: the header and no node
  return header.str() + nodes;
}

// One node of OctoMap's node data: its log-odds, then which children follow.
std::string node(float log_odds, std::uint8_t children) {
  std::string bytes(sizeof log_odds, '\0');
  std::memcpy(bytes.data(), &log_odds, sizeof log_odds);
  return bytes + static_cast<char>(children);
}

// A path of single children from the root down to level `depth` (exclusive), whose last node has the
// children `last_children`.
std::string path_to(unsigned depth, std::uint8_t last_children) {
  std::string nodes;
  for (unsigned level = 0; level + 1 < depth; ++level) nodes += node(2.0f, 0x01);
  return nodes + node(2.0f, last_children);
}

OccupancyMap read_map(const std::string& saved) {
  std::istringstream in(saved);
  OccupancyMap map;
  map.read(in);
  return map;
}

// Why read() refuses `saved` ("" if it reads it).
std::string refusal_of(const std::string& saved) {
  return test::error_of([&] { (void)read_map(saved); });
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

TEST(OccupancyMapStateTest, ReadRefusesAMapThatUnpacksToMoreOccupiedVoxelsThanTheLimit) {
  // Pruned occupied leaves at level 9 of 16 stand for 8⁷ = 2²¹ voxels each: two are the limit, three beyond.
  static_assert(OccupancyMap::kMaxSavedOccupiedVoxels == 2 * (std::uint64_t{1} << 21));
  const OccupancyMap two = read_map(saved_map(path_to(9, 0x03) + node(2.0f, 0) + node(2.0f, 0)));
  EXPECT_EQ(two.tree().getNumLeafNodes(), 2u);
  std::size_t occupied_leaves = 0;
  for (auto it = two.tree().begin_leafs(); it != two.tree().end_leafs(); ++it)
    occupied_leaves += two.tree().isNodeOccupied(*it) ? 1 : 0;
  EXPECT_EQ(occupied_leaves, 2u);
  // A free third leaf counts nothing; an occupied one is refused, as is one node for 8¹⁵ voxels.
  EXPECT_EQ(refusal_of(saved_map(path_to(9, 0x07) + node(2.0f, 0) + node(2.0f, 0) + node(-2.0f, 0))), "");
  const std::string too_many = "occupancy map: the saved map holds more than 4194304 occupied voxels";
  EXPECT_EQ(
      refusal_of(saved_map(path_to(9, 0x07) + node(2.0f, 0) + node(2.0f, 0) + node(2.0f, 0))).find(too_many),
      0u);
  EXPECT_EQ(refusal_of(saved_map(node(2.0f, 0x01) + node(2.0f, 0))).find(too_many), 0u);
}

TEST(OccupancyMapStateTest, ReadRefusesNodeDataOctoMapWouldMisread) {
  const std::string leaf_at_16 = path_to(16, 0x01) + node(2.0f, 0);
  EXPECT_EQ(refusal_of(saved_map(leaf_at_16)), "");
  // One level deeper than the tree, a log-odds that is not a number, a node cut short, a child missing.
  EXPECT_EQ(refusal_of(saved_map(path_to(17, 0x01) + node(2.0f, 0))),
            "occupancy map: the saved map is deeper than the tree");
  std::string not_a_number = leaf_at_16;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(not_a_number.data() + not_a_number.size() - 5, &nan, sizeof nan);
  EXPECT_EQ(refusal_of(saved_map(not_a_number)),
            "occupancy map: the saved map holds a log-odds that is not finite");
  const std::string truncated = "occupancy map: the saved map is truncated";
  EXPECT_EQ(refusal_of(saved_map(leaf_at_16.substr(0, leaf_at_16.size() - 1))), truncated);
  EXPECT_EQ(refusal_of(saved_map(path_to(16, 0x03) + node(2.0f, 0))), truncated);
}

TEST(OccupancyMapStateTest, AnEmptyMapReadsBackEmpty) {
  const OccupancyMap map = read_map(saved_map(""));
  EXPECT_EQ(map.tree().size(), 0u);
  EXPECT_TRUE(map.occupied_keys().empty());
}

}  // namespace
}  // namespace cellmap
