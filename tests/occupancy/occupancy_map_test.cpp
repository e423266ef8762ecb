// SPDX-License-Identifier: Apache-2.0
#include "cellmap/occupancy/occupancy_map.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <set>

#include "cellmap/common/error.hpp"
#include "occupancy/box_scene.hpp"
#include "occupancy/octomap_cloud.hpp"
#include "tree_agreement.hpp"

namespace cellmap {
namespace {

using testing::AlignedBox;

using testing::to_octomap;

Eigen::Isometry3d camera_at(const Eigen::Vector3d& p_C, double pitch) {
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  X_CS.translate(p_C);
  X_CS.rotate(Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()));
  return X_CS;
}

Sweep sweep_of(const std::vector<AlignedBox>& scene, const std::vector<Eigen::Isometry3d>& poses,
               int width = 120, int height = 90) {
  Sweep sweep;
  for (const Eigen::Isometry3d& X_CS : poses) {
    sweep.scans.push_back(testing::render_scan(scene, X_CS, testing::kinect_intrinsics(width, height)));
  }
  return sweep;
}

TEST(OccupancyMapTest, MatchesOctomapsOwnInsertOverSeveralSweeps) {
  OccupancyConfig config;
  config.resolution = 0.05;
  OccupancyMap map(config);
  octomap::OcTree reference(config.resolution);
  apply_sensor_model(config, reference);
  const std::vector<Eigen::Isometry3d> poses = {camera_at({0.011, -0.2, 0.02}, -0.25),
                                                camera_at({0.4, -0.3, 0.3}, -0.35),
                                                camera_at({-0.37, -0.1, 0.21}, -0.1)};
  std::vector<AlignedBox> scene = testing::box_room();
  for (int sweep = 0; sweep < 5; ++sweep) {
    if (sweep == 3) scene.pop_back();  // box B leaves: its voxels get free-space evidence from then on
    const Scan scan = testing::render_scan(scene, poses[std::size_t(sweep) % poses.size()],
                                           testing::kinect_intrinsics(96, 72));
    Sweep one;
    one.scans.push_back(scan);
    map.integrate(one);
    const octomap::point3d origin(float(scan.origin_C.x()), float(scan.origin_C.y()),
                                  float(scan.origin_C.z()));
    reference.insertPointCloud(to_octomap(scan), origin, config.max_range, false, true);
  }
  const TreeAgreement agreement = compare_trees(map.tree(), reference);
  EXPECT_GT(agreement.voxels, 5000u);
  EXPECT_GE(agreement.fraction(), 0.999);
  EXPECT_EQ(agreement.same, agreement.voxels);  // measured: identical, voxel for voxel
  EXPECT_EQ(agreement.same_log_odds, agreement.voxels);
  EXPECT_EQ(agreement.occupied_a, agreement.occupied_b);
}

// Clear-only ray ends 0.2 m before the points of `scan` that lie in box B (box_room's second box), those
// points taken out: the line of sight up to the robot, as the self filter leaves it.
void make_box_b_clear_only(Scan& scan) {
  Cloud kept;
  for (const auto& p : scan.points_C) {
    if (p.x > 0.3f && p.x < 0.7f && p.z > 2.35f && p.z < 2.85f && p.y > 0.65f && p.y < 0.99f) {
      const Eigen::Vector3d p_C(p.x, p.y, p.z);
      const Eigen::Vector3d end_C = p_C - 0.2 * (p_C - scan.origin_C).normalized();
      scan.clear_C.push_back(pcl::PointXYZ(float(end_C.x()), float(end_C.y()), float(end_C.z())));
    } else {
      kept.push_back(p);
    }
  }
  scan.points_C = kept;
}

// Clear-only rays through the map: the same tree as OctoMap's updateNode fed with computeRayKeys free keys.
TEST(OccupancyMapTest, ClearOnlyRaysMatchOctomapsUpdateNode) {
  OccupancyConfig config;
  config.resolution = 0.05;
  OccupancyMap map(config);
  octomap::OcTree reference(config.resolution);
  apply_sensor_model(config, reference);
  std::vector<octomap::OcTreeKey> box_b;  // box B's voxels occupied after the first sweep
  for (int sweep = 0; sweep < 3; ++sweep) {
    if (sweep == 1) {
      for (const octomap::OcTreeKey& k : map.occupied_keys()) {
        const Eigen::Vector3d c = map.centre(k);
        if (c.x() > 0.3 && c.x() < 0.7 && c.z() > 2.35 && c.z() < 2.85 && c.y() > 0.65 && c.y() < 0.99) {
          box_b.push_back(k);
        }
      }
    }
    Scan scan = testing::render_scan(testing::box_room(), camera_at({0.011 * sweep, -0.2, 0.02}, -0.25),
                                     testing::kinect_intrinsics(96, 72));
    if (sweep > 0) make_box_b_clear_only(scan);  // later sweeps: box B's points become clear-only rays
    ASSERT_EQ(scan.clear_C.empty(), sweep == 0);
    Sweep one;
    one.scans.push_back(scan);
    map.integrate(one);
    // The reference: each distinct voxel once per sweep, occupied winning (OctoMap's discrete update).
    const octomap::point3d origin(float(scan.origin_C.x()), float(scan.origin_C.y()),
                                  float(scan.origin_C.z()));
    octomap::KeySet free, occupied, hit_voxels, clear_voxels;
    reference.computeDiscreteUpdate(to_octomap(scan), origin, free, occupied, config.max_range);
    for (const auto& p : scan.points_C) hit_voxels.insert(reference.coordToKey(p.x, p.y, p.z));
    for (const auto& p : scan.clear_C) clear_voxels.insert(reference.coordToKey(p.x, p.y, p.z));
    for (const octomap::OcTreeKey& k : clear_voxels) {
      octomap::KeyRay ray;
      if (hit_voxels.count(k) == 0 && reference.computeRayKeys(origin, reference.keyToCoord(k), ray)) {
        free.insert(ray.begin(), ray.end());
      }
    }
    for (const octomap::OcTreeKey& k : free) {
      if (occupied.count(k) == 0) reference.updateNode(k, false, true);
    }
    for (const octomap::OcTreeKey& k : occupied) reference.updateNode(k, true, true);
    reference.updateInnerOccupancy();
  }
  const TreeAgreement agreement = compare_trees(map.tree(), reference);
  EXPECT_GT(agreement.voxels, 3000u);
  EXPECT_EQ(agreement.same, agreement.voxels);
  EXPECT_EQ(agreement.same_log_odds, agreement.voxels);
  EXPECT_EQ(agreement.occupied_a, agreement.occupied_b);
  // Box B: hit once, then its points became clear-only rays that stop before it: its voxels stay occupied
  // (nothing cleared them), while the space in front of it got the clear-only rays' free-space evidence.
  ASSERT_GT(box_b.size(), 20u);
  std::size_t still_occupied = 0;
  for (const octomap::OcTreeKey& k : box_b) still_occupied += map.state(k) == VoxelState::occupied ? 1 : 0;
  EXPECT_EQ(still_occupied, box_b.size());
  EXPECT_EQ(map.state(Eigen::Vector3d(0.5, 0.6, 2.3)), VoxelState::free);
}

// Every leaf voxel known in `a` or `b` (pruned nodes expanded) with its log-odds in both; the count of those
// that differ.
std::size_t log_odds_differences(const octomap::OcTree& a, const octomap::OcTree& b, std::size_t& known) {
  std::size_t differences = 0;
  known = 0;
  for (const octomap::OcTree* tree : {&a, &b}) {
    const octomap::OcTree& other = tree == &a ? b : a;
    for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
      const int span = 1 << (tree->getTreeDepth() - it.getDepth());
      const octomap::OcTreeKey first = it.getIndexKey();
      for (int z = 0; z < span; ++z)
        for (int y = 0; y < span; ++y)
          for (int x = 0; x < span; ++x) {
            const octomap::OcTreeNode* node =
                other.search(octomap::OcTreeKey(first[0] + x, first[1] + y, first[2] + z));
            ++known;
            if (node == nullptr || node->getLogOdds() != it->getLogOdds()) ++differences;
          }
    }
  }
  return differences;
}

// A sweep's scans gathered one by one as its frames arrive make the map the whole sweep makes at once,
// log-odds for log-odds, with the same flips: over several sweeps of three overlapping views (one with
// clear-only rays through voxels another view hits), while a box leaves. The flips are all the occupied
// set's changes.
TEST(OccupancyMapTest, ScansGatheredOneByOneMakeTheWholeSweepsMap) {
  OccupancyConfig config;
  config.resolution = 0.05;
  OccupancyMap whole(config), gathered(config);
  ObservedVoxels voxels(config);
  const std::vector<Eigen::Isometry3d> poses = {camera_at({0.011, -0.2, 0.02}, -0.25),
                                                camera_at({0.4, -0.3, 0.3}, -0.35),
                                                camera_at({-0.37, -0.1, 0.21}, -0.1)};
  std::vector<AlignedBox> scene = testing::box_room();
  std::size_t flips = 0;
  std::set<std::uint64_t> occupied;
  const auto packed = [](const octomap::OcTreeKey& k) {
    return std::uint64_t{k[0]} | std::uint64_t{k[1]} << 16 | std::uint64_t{k[2]} << 32;
  };
  for (int sweep = 0; sweep < 5; ++sweep) {
    if (sweep == 3) scene.pop_back();  // box B leaves
    Sweep frames = sweep_of(scene, poses, 96, 72);
    make_box_b_clear_only(frames.scans[0]);
    ASSERT_EQ(frames.scans[0].clear_C.empty(), sweep >= 3);
    const OccupancyUpdate expected = whole.integrate(frames);
    for (Scan& scan : frames.scans) voxels.add(std::move(scan));
    EXPECT_EQ(voxels.scans(), 3u);
    EXPECT_GT(voxels.bricks(), 0u);
    const OccupancyUpdate update = gathered.integrate(voxels);
    EXPECT_EQ(voxels.scans(), 0u);
    EXPECT_EQ(voxels.bricks(), 0u) << "integrate() empties the gathered voxels for the next sweep";
    EXPECT_EQ(update.hit_voxels, expected.hit_voxels);
    EXPECT_EQ(update.free_voxels, expected.free_voxels);
    EXPECT_EQ(update.appeared, expected.appeared);
    EXPECT_EQ(update.vanished, expected.vanished);
    flips += update.appeared.size() + update.vanished.size();
    // The flips reported are every change of the occupied set: a set kept by them is the map's.
    for (const octomap::OcTreeKey& key : update.vanished) EXPECT_EQ(occupied.erase(packed(key)), 1u);
    for (const octomap::OcTreeKey& key : update.appeared) EXPECT_TRUE(occupied.insert(packed(key)).second);
    std::set<std::uint64_t> now;
    for (const octomap::OcTreeKey& key : gathered.occupied_keys()) now.insert(packed(key));
    EXPECT_EQ(now, occupied) << "sweep " << sweep;
  }
  EXPECT_GT(flips, 100u) << "the sweeps flipped too little to compare";
  const TreeAgreement agreement = compare_trees(gathered.tree(), whole.tree());
  EXPECT_GT(agreement.voxels, 5000u);
  EXPECT_EQ(agreement.same_log_odds, agreement.voxels);
  EXPECT_EQ(agreement.occupied_a, agreement.occupied_b);
}

TEST(OccupancyMapTest, GatheredVoxelsOfAnotherResolutionAreRefused) {
  OccupancyConfig coarse;
  coarse.resolution = 0.05;
  OccupancyMap map;  // 2 cm
  ObservedVoxels voxels(coarse);
  voxels.add(sweep_of(testing::box_room(), {camera_at({0.0, -0.2, 0.0}, -0.25)}, 48, 36).scans[0]);
  EXPECT_THROW(
      {
        try {
          (void)map.integrate(voxels);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
          throw;
        }
      },
      Error);
  EXPECT_EQ(map.tree().size(), 0u) << "nothing was fused";
}

TEST(OccupancyMapTest, AScanWhoseOriginIsOutsideTheMapAddsNothing) {
  ObservedVoxels voxels;
  Scan scan = sweep_of(testing::box_room(), {camera_at({0.0, -0.2, 0.0}, -0.25)}, 48, 36).scans[0];
  scan.origin_C = Eigen::Vector3d(1e6, 0.0, 0.0);
  EXPECT_THROW(voxels.add(std::move(scan)), Error);
  EXPECT_EQ(voxels.scans(), 0u);
  EXPECT_EQ(voxels.bricks(), 0u);
}

// Whole free subtrees (new, or pruned after reaching the clamp bound) are updated as one node: every leaf
// below ends with updateNode()'s log-odds, also where a removed box's voxels inside pruned free space and
// the clamp bounds come into play over many sweeps.
TEST(OccupancyMapTest, WholeSubtreesGetUpdateNodesLogOdds) {
  OccupancyConfig config;
  config.resolution = 0.05;
  OccupancyMap map(config);
  octomap::OcTree reference(config.resolution);
  apply_sensor_model(config, reference);
  std::vector<AlignedBox> scene = testing::box_room();
  for (int sweep = 0; sweep < 12; ++sweep) {
    if (sweep == 8) scene.pop_back();
    const Scan scan = testing::render_scan(scene, camera_at({0.011, -0.2, 0.02}, -0.25 + 0.01 * (sweep % 3)),
                                           testing::kinect_intrinsics(160, 120));
    Sweep one;
    one.scans.push_back(scan);
    map.integrate(one);
    const octomap::point3d origin(float(scan.origin_C.x()), float(scan.origin_C.y()),
                                  float(scan.origin_C.z()));
    octomap::KeySet free, occupied;
    reference.computeDiscreteUpdate(to_octomap(scan), origin, free, occupied, config.max_range);
    for (const octomap::OcTreeKey& k : free) {
      if (occupied.count(k) == 0) reference.updateNode(k, false, false);
    }
    for (const octomap::OcTreeKey& k : occupied) reference.updateNode(k, true, false);
  }
  std::size_t known = 0;
  EXPECT_EQ(log_odds_differences(map.tree(), reference, known), 0u);
  EXPECT_GT(known, 20000u);
  // Pruned: our tree holds no more nodes than OctoMap's own non-lazy updates leave.
  EXPECT_LE(map.tree().size(), reference.size());
}

TEST(OccupancyMapTest, ReportsFlipsAndStates) {
  OccupancyMap map;
  const std::vector<AlignedBox> scene = {{{-1, -1, 2.0}, {1, 1, 2.1}}};  // a wall 2 m ahead
  const Sweep sweep = sweep_of(scene, {Eigen::Isometry3d::Identity()});
  const OccupancyUpdate first = map.integrate(sweep);
  EXPECT_GT(first.hit_voxels, 0u);
  EXPECT_EQ(first.appeared.size(), first.hit_voxels);  // unknown → occupied
  EXPECT_TRUE(first.vanished.empty());
  EXPECT_EQ(map.occupied_keys(), first.appeared);
  EXPECT_EQ(map.state(Eigen::Vector3d(0.01, 0.01, 2.01)), VoxelState::occupied);
  EXPECT_EQ(map.state(Eigen::Vector3d(0.01, 0.01, 1.0)), VoxelState::free);
  EXPECT_EQ(map.state(Eigen::Vector3d(0.01, 0.01, 3.0)), VoxelState::unknown);
  EXPECT_EQ(map.state(Eigen::Vector3d(std::nan(""), 0, 0)), VoxelState::unknown);
  // Occupied evidence in a box: the wall voxels whose centres lie in it (checked against a full scan).
  const Eigen::Vector3d lo(-0.1, -0.1, 1.9), hi(0.1, 0.1, 2.1);
  const std::vector<Eigen::Vector3d> in_box = map.occupied_centres_in(lo, hi);
  std::size_t expected = 0;
  for (const octomap::OcTreeKey& key : map.occupied_keys()) {
    const Eigen::Vector3d c = map.centre(key);
    expected += (c.array() >= lo.array()).all() && (c.array() <= hi.array()).all();
  }
  EXPECT_EQ(in_box.size(), expected);
  EXPECT_GT(in_box.size(),
            60u);  // of the 10 × 10 voxel centres there (the 120-pixel frame misses a few columns)
  for (const Eigen::Vector3d& c : in_box) EXPECT_NEAR(c.z(), 2.01, 1e-9);  // the hit layer, z in [2.00, 2.02)
  EXPECT_TRUE(map.occupied_centres_in({-0.1, -0.1, 1.0}, {0.1, 0.1, 1.5}).empty());
  const OccupancyUpdate second = map.integrate(sweep);
  EXPECT_TRUE(second.appeared.empty());
  EXPECT_TRUE(second.vanished.empty());
  // Newly observed: every voxel the first sweep made known (leaves of pruned blocks counted whole), none of
  // the second, which looked at the same space.
  std::size_t known = 0;
  for (auto it = map.tree().begin_leafs(), end = map.tree().end_leafs(); it != end; ++it) {
    known += std::size_t{1} << (3 * (map.tree().getTreeDepth() - it.getDepth()));
  }
  EXPECT_EQ(first.newly_observed, known);
  EXPECT_EQ(second.newly_observed, 0u);
  const OccupancyUpdate aside = map.integrate(sweep_of(scene, {camera_at({0, 0, 0}, 0.6)}));
  EXPECT_GT(aside.newly_observed, 0u);  // tilted, it sees space beside the first view's
}

// A removed object vanishes after exactly config.sweeps_to_clear() sweeps that see through it.
TEST(OccupancyMapTest, RemovedBoxClearsAfterDocumentedSweeps) {
  OccupancyConfig config;
  config.resolution = 0.04;
  OccupancyMap map(config);
  const AlignedBox box{{-0.2, 0.6, 1.51}, {0.2, 1.0, 1.9}};
  std::vector<AlignedBox> scene = {{{-2, 1.0, 0}, {2, 1.1, 4}}, {{-2, -1.5, 3.0}, {2, 1.1, 3.1}}, box};
  const std::vector<Eigen::Isometry3d> poses = {camera_at({0, -0.3, 0}, -0.35)};  // looking down
  // 320 × 240: rays dense enough (< 1 cm apart at 2 m) that every voxel of the box is crossed once it is
  // gone; coarser frames leave voxels that no discretized ray crosses, which then never clear.
  auto sweep = [&] { return sweep_of(scene, poses, 320, 240); };
  // Saturate: a voxel hit in every sweep reaches the upper clamp after 5 sweeps (5 · 0.85 > 3.5).
  for (int i = 0; i < 6; ++i) map.integrate(sweep());
  const Eigen::Vector3d front_C(0.01, 0.81, 1.515);  // in the voxel of the box's front face
  ASSERT_EQ(map.state(front_C), VoxelState::occupied);

  scene.pop_back();
  const int n = map.config().sweeps_to_clear();
  ASSERT_EQ(n, 9);
  std::size_t vanished = 0;
  for (int i = 1; i <= n; ++i) {
    const OccupancyUpdate update = map.integrate(sweep());
    vanished += update.vanished.size();
    if (i < n) {
      EXPECT_EQ(map.state(front_C), VoxelState::occupied) << "sweep " << i;
      EXPECT_EQ(vanished, 0u) << "sweep " << i;
    }
  }
  EXPECT_EQ(map.state(front_C), VoxelState::free);
  EXPECT_GT(vanished, 50u);
  for (const octomap::OcTreeKey& key : map.occupied_keys()) {
    const Eigen::Vector3d p_C = map.centre(key);
    const bool inside_box = (p_C.array() > box.min_C.array() - 0.04).all() &&
                            (p_C.array() < box.max_C.array() + 0.04).all() && p_C.y() < 0.96;
    EXPECT_FALSE(inside_box) << "voxel at " << p_C.transpose() << " still occupied";
  }
}

TEST(OccupancyMapTest, RejectsBadConfigAndOrigins) {
  OccupancyConfig config;
  config.miss = 0.6;
  EXPECT_THROW(OccupancyMap{config}, Error);
  OccupancyMap map;
  Sweep sweep;
  sweep.scans.emplace_back();
  sweep.scans[0].origin_C = Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0, 0);
  sweep.scans[0].points_C.push_back(pcl::PointXYZ(1, 0, 0));
  EXPECT_THROW(map.integrate(sweep), Error);
  EXPECT_EQ(map.tree().size(), 0u);
}

}  // namespace
}  // namespace cellmap
