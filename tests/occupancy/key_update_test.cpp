// SPDX-License-Identifier: Apache-2.0
#include "key_update.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>
#include <utility>

#include "cellmap/common/error.hpp"
#include "occupancy/box_scene.hpp"
#include "occupancy/octomap_cloud.hpp"

namespace cellmap {
namespace {

using Keys = std::vector<octomap::OcTreeKey>;

Keys sorted(const octomap::KeySet& set) {
  Keys keys(set.begin(), set.end());
  std::sort(keys.begin(), keys.end(), [](const octomap::OcTreeKey& a, const octomap::OcTreeKey& b) {
    return std::make_tuple(a[2], a[1], a[0]) < std::make_tuple(b[2], b[1], b[0]);
  });
  return keys;
}

using testing::to_octomap;

octomap::point3d origin_of(const Scan& scan) {
  return octomap::point3d(float(scan.origin_C.x()), float(scan.origin_C.y()), float(scan.origin_C.z()));
}

// A camera 1.2 m above the floor of the box room, looking in along +z, tilted down and slightly yawed, at a
// position that is not on a voxel corner.
Eigen::Isometry3d tilted_pose() {
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  X_CS.translate(Eigen::Vector3d(0.013, -0.2071, 0.0337));
  X_CS.rotate(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()) *
              Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  return X_CS;
}

Sweep one_scan(const Eigen::Isometry3d& X_CS, int width = 96, int height = 72) {
  Sweep sweep;
  sweep.scans.push_back(
      testing::render_scan(testing::box_room(), X_CS, testing::kinect_intrinsics(width, height)));
  return sweep;
}

// OctoMap's own keys for a sweep: computeDiscreteUpdate per scan, united, occupied winning over free.
std::pair<octomap::KeySet, octomap::KeySet> octomap_sweep_update(const Sweep& sweep, octomap::OcTree& tree) {
  octomap::KeySet free, occupied;
  for (const Scan& scan : sweep.scans) {
    octomap::KeySet scan_free, scan_occupied;
    tree.computeDiscreteUpdate(to_octomap(scan), origin_of(scan), scan_free, scan_occupied, 5.0);
    free.insert(scan_free.begin(), scan_free.end());
    occupied.insert(scan_occupied.begin(), scan_occupied.end());
  }
  for (const octomap::OcTreeKey& k : occupied) free.erase(k);
  return {free, occupied};
}

TEST(KeyUpdateTest, EqualsOctomapsDiscreteUpdateForOneScan) {
  octomap::OcTree tree(0.04);
  for (const Eigen::Isometry3d& X_CS : {Eigen::Isometry3d::Identity(), tilted_pose()}) {
    for (const double max_range : {5.0, 2.5}) {  // 2.5 m truncates the rays to the back wall
      const Sweep sweep = one_scan(X_CS);
      octomap::KeySet free, occupied;
      tree.computeDiscreteUpdate(to_octomap(sweep.scans[0]), origin_of(sweep.scans[0]), free, occupied,
                                 max_range);
      const KeyUpdate ours = compute_key_update(sweep, tree, max_range, 2);
      EXPECT_EQ(ours.occupied_keys(), sorted(occupied));
      EXPECT_EQ(ours.free_keys(), sorted(free));
      EXPECT_EQ(ours.occupied_count, occupied.size());
      EXPECT_EQ(ours.free_count, free.size());
      EXPECT_GT(free.size(), 1000u);
    }
  }
}

// A scan whose points right of x = 0.2 m (cell frame) become clear-only rays ending 0.3 m short of the point,
// as the self filter turns measurements of the robot into rays that stop at its near surface; a few clear
// ends share a voxel with a kept point.
Scan with_clear_rays(Scan scan) {
  Cloud kept;
  for (const pcl::PointXYZ& p : scan.points_C) {
    if (p.x <= 0.2f) {
      kept.push_back(p);
      continue;
    }
    const Eigen::Vector3d p_C(p.x, p.y, p.z);
    const Eigen::Vector3d end_C = p_C - 0.3 * (p_C - scan.origin_C).normalized();
    scan.clear_C.push_back(pcl::PointXYZ(float(end_C.x()), float(end_C.y()), float(end_C.z())));
  }
  for (std::size_t i = 0; i < kept.size(); i += 97) scan.clear_C.push_back(kept[i]);
  scan.points_C = kept;
  return scan;
}

// OctoMap's own keys for one scan with clear-only rays: computeDiscreteUpdate for the points, and for every
// distinct clear-ray end voxel that holds no point computeRayKeys from the origin to its centre (cut at
// max_range as OctoMap cuts a point's ray); occupied wins.
std::pair<octomap::KeySet, octomap::KeySet> octomap_update_with_clear_rays(const Scan& scan,
                                                                           octomap::OcTree& tree,
                                                                           double max_range) {
  octomap::KeySet free, occupied;
  tree.computeDiscreteUpdate(to_octomap(scan), origin_of(scan), free, occupied, max_range);
  octomap::KeySet point_voxels;
  for (const auto& p : scan.points_C) point_voxels.insert(tree.coordToKey(p.x, p.y, p.z));
  octomap::KeySet clear_voxels;
  for (const auto& p : scan.clear_C) clear_voxels.insert(tree.coordToKey(p.x, p.y, p.z));
  const octomap::point3d origin = origin_of(scan);
  for (const octomap::OcTreeKey& k : clear_voxels) {
    if (point_voxels.count(k) != 0) continue;
    octomap::point3d end = tree.keyToCoord(k);
    if ((end - origin).norm() > max_range) end = origin + (end - origin).normalized() * float(max_range);
    octomap::KeyRay ray;
    if (tree.computeRayKeys(origin, end, ray)) free.insert(ray.begin(), ray.end());
  }
  for (const octomap::OcTreeKey& k : occupied) free.erase(k);
  return {free, occupied};
}

TEST(KeyUpdateTest, ClearOnlyRaysEqualOctomapsRayKeys) {
  octomap::OcTree tree(0.04);
  for (const double max_range : {5.0, 2.5}) {
    Sweep sweep;
    sweep.scans.push_back(with_clear_rays(one_scan(tilted_pose()).scans[0]));
    ASSERT_GT(sweep.scans[0].clear_C.size(), 1000u);
    const auto [free, occupied] = octomap_update_with_clear_rays(sweep.scans[0], tree, max_range);
    const KeyUpdate ours = compute_key_update(sweep, tree, max_range, 2);
    EXPECT_EQ(ours.occupied_keys(), sorted(occupied));
    EXPECT_EQ(ours.free_keys(), sorted(free));
    // The clear-only rays cleared voxels the points alone did not, and marked none occupied.
    const Sweep points_only = one_scan(tilted_pose());
    Sweep kept_only = sweep;
    kept_only.scans[0].clear_C.clear();
    EXPECT_GT(ours.free_count, compute_key_update(kept_only, tree, max_range, 2).free_count);
    EXPECT_LE(ours.occupied_count, compute_key_update(points_only, tree, max_range, 2).occupied_count);
  }
}

// A clear-only ray ends in a voxel that is neither hit nor cleared, and a ray whose end is in the origin's
// voxel clears nothing.
TEST(KeyUpdateTest, ClearOnlyRayStopsBeforeItsEndVoxel) {
  octomap::OcTree tree(0.1);
  Sweep sweep;
  sweep.scans.emplace_back();
  sweep.scans[0].clear_C.push_back(pcl::PointXYZ(1.05f, 0.05f, 0.05f));
  sweep.scans[0].clear_C.push_back(pcl::PointXYZ(0.02f, 0.03f, 0.04f));
  const KeyUpdate update = compute_key_update(sweep, tree, 5.0, 2);
  EXPECT_EQ(update.occupied_count, 0u);
  EXPECT_EQ(update.free_count, 10u);  // x in [0, 1.0): the origin voxel and the 9 after it
  const Keys free = update.free_keys();
  EXPECT_EQ(std::count(free.begin(), free.end(), tree.coordToKey(1.05, 0.05, 0.05)), 0);
  EXPECT_EQ(std::count(free.begin(), free.end(), tree.coordToKey(0.95, 0.05, 0.05)), 1);
}

// Each thread de-duplicates its own share of the points and clear-only ends: voxels shared by two shares
// get their ray twice, which must not change the result.
TEST(KeyUpdateTest, ResultDoesNotDependOnThreads) {
  octomap::OcTree tree(0.05);
  Sweep with_clear;
  with_clear.scans.push_back(with_clear_rays(one_scan(tilted_pose()).scans[0]));
  for (const Sweep& sweep : {one_scan(tilted_pose()), with_clear}) {
    const KeyUpdate one = compute_key_update(sweep, tree, 5.0, 1);
    for (const int threads : {2, 3, 7}) {
      const KeyUpdate many = compute_key_update(sweep, tree, 5.0, threads);
      EXPECT_EQ(many.occupied_keys(), one.occupied_keys());
      EXPECT_EQ(many.free_keys(), one.free_keys());
      EXPECT_EQ(many.free_count, one.free_count);
    }
  }
}

TEST(KeyUpdateTest, SeveralScansUniteWithOccupiedWinning) {
  octomap::OcTree tree(0.04);
  Sweep sweep = one_scan(Eigen::Isometry3d::Identity(), 80, 60);
  sweep.scans.push_back(one_scan(tilted_pose(), 80, 60).scans[0]);
  const auto [free, occupied] = octomap_sweep_update(sweep, tree);
  const KeyUpdate ours = compute_key_update(sweep, tree, 5.0, 2);
  EXPECT_EQ(ours.occupied_keys(), sorted(occupied));
  EXPECT_EQ(ours.free_keys(), sorted(free));
}

// Scans 150 m apart span more than 2^28 voxels: the sorted-key fallback must give the same result.
TEST(KeyUpdateTest, HugeSweepBoxFallsBackToSortingWithSameResult) {
  octomap::OcTree tree(0.01);
  Sweep sweep;
  for (const double offset : {0.0, 150.0}) {
    Scan scan;
    scan.origin_C = Eigen::Vector3d(offset + 0.003, offset - 0.002, 0.001);
    for (int i = 0; i < 20; ++i) {
      scan.points_C.push_back(
          pcl::PointXYZ(float(offset + 0.5 + 0.01 * i), float(offset + 0.2 - 0.03 * i), 0.1f));
    }
    sweep.scans.push_back(scan);
  }
  const auto [free, occupied] = octomap_sweep_update(sweep, tree);
  const KeyUpdate ours = compute_key_update(sweep, tree, 5.0, 2);
  EXPECT_EQ(ours.occupied_keys(), sorted(occupied));
  EXPECT_EQ(ours.free_keys(), sorted(free));
  EXPECT_EQ(ours.occupied_count, occupied.size());
  EXPECT_GT(free.size(), 100u);
}

// One scan whose points lie more than 200 m apart spans more than 2^28 voxels: its end voxels are
// de-duplicated by sorting, and the far points' rays are cut at max_range.
TEST(KeyUpdateTest, HugeScanBoxFallsBackToSortingWithSameResult) {
  octomap::OcTree tree(0.01);
  Sweep sweep;
  Scan& scan = sweep.scans.emplace_back();
  scan.origin_C = Eigen::Vector3d(0.003, -0.002, 0.001);
  for (const double offset : {0.0, 150.0}) {
    for (int i = 0; i < 20; ++i) {
      scan.points_C.push_back(pcl::PointXYZ(float(offset + 0.5 + 0.01 * i), float(0.2 - 0.03 * i - offset),
                                            float(0.1 + 0.1 * offset)));
    }
  }
  const auto [free, occupied] = octomap_sweep_update(sweep, tree);
  for (const int threads : {1, 2}) {
    const KeyUpdate ours = compute_key_update(sweep, tree, 5.0, threads);
    EXPECT_EQ(ours.occupied_keys(), sorted(occupied));
    EXPECT_EQ(ours.free_keys(), sorted(free));
  }
  EXPECT_EQ(occupied.size(), 20u);
  EXPECT_GT(free.size(), 500u);
}

TEST(KeyUpdateTest, SkipsNonFinitePointsAndRejectsBadOrigins) {
  octomap::OcTree tree(0.1);
  Sweep sweep;
  sweep.scans.emplace_back();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  sweep.scans[0].points_C.push_back(pcl::PointXYZ(nan, 0, 0));
  sweep.scans[0].points_C.push_back(pcl::PointXYZ(1.05f, 0.05f, 0.05f));
  sweep.scans[0].points_C.push_back(pcl::PointXYZ(1e9f, 0, 0));  // outside the key range
  const KeyUpdate update = compute_key_update(sweep, tree, 5.0, 2);
  // Origin voxel (0,0,0)..(0.1) and the 9 voxels up to x = 1.0 are free, the voxel at x = 1.05 is occupied.
  ASSERT_EQ(update.occupied_keys().size(), 1u);
  EXPECT_EQ(update.occupied_keys()[0], tree.coordToKey(1.05, 0.05, 0.05));
  EXPECT_EQ(update.free_count, 10u);

  sweep.scans[0].origin_C = Eigen::Vector3d(std::nan(""), 0, 0);
  EXPECT_THROW((void)compute_key_update(sweep, tree, 5.0, 1), Error);
  sweep.scans[0].origin_C = Eigen::Vector3d(1e7, 0, 0);
  EXPECT_THROW((void)compute_key_update(sweep, tree, 5.0, 1), Error);
  sweep.scans[0].origin_C = Eigen::Vector3d::Zero();
  EXPECT_THROW((void)compute_key_update(sweep, tree, 0.0, 1), Error);
}

// Points one float step either side of and exactly on voxel borders, in a row (so that each is compared with
// the voxel of the one before it): every point lands in OctoMap's voxel for it, as coordToKey says.
TEST(KeyUpdateTest, PointsAtVoxelBordersGetOctomapsKeys) {
  octomap::OcTree tree(0.02);
  Sweep sweep;
  Scan& scan = sweep.scans.emplace_back();
  scan.origin_C = Eigen::Vector3d(0.005, 0.007, 0.003);
  const float inf = std::numeric_limits<float>::infinity();
  for (int k = -60; k <= 60; ++k) {
    const float border = static_cast<float>(k * 0.02);
    const float other = static_cast<float>(-k * 0.02 + 0.04);
    for (const float x : {std::nextafter(border, -inf), border, std::nextafter(border, inf)}) {
      for (const float y : {std::nextafter(other, -inf), other, std::nextafter(other, inf)}) {
        scan.points_C.push_back(pcl::PointXYZ(x, y, 0.5f));
        scan.points_C.push_back(pcl::PointXYZ(y, 0.5f, x));
      }
    }
  }
  octomap::KeySet expected;
  for (const auto& p : scan.points_C) expected.insert(tree.coordToKey(p.x, p.y, p.z));
  const KeyUpdate ours = compute_key_update(sweep, tree, 5.0, 1);
  EXPECT_EQ(ours.occupied_keys(), sorted(expected));
  EXPECT_GT(expected.size(), 700u);
}

// Rays cut at max_range whose cut ends lie on voxel faces, edges and corners (along the axes and diagonals
// from a voxel centre and from a voxel corner), where rounding decides whether the walk enters the end voxel
// or stops beside it: the same free voxels as OctoMap's computeDiscreteUpdate.
TEST(KeyUpdateTest, RaysCutOnVoxelFacesEqualOctomap) {
  octomap::OcTree tree(0.02);
  for (const Eigen::Vector3d& origin : {Eigen::Vector3d(0.01, 0.01, 0.01), Eigen::Vector3d(0.0, 0.0, 0.0)}) {
    Sweep sweep;
    Scan& scan = sweep.scans.emplace_back();
    scan.origin_C = origin;
    for (int x = -2; x <= 2; ++x) {
      for (int y = -2; y <= 2; ++y) {
        for (int z = -1; z <= 1; ++z) {
          if (x == 0 && y == 0 && z == 0) continue;
          const Eigen::Vector3d p = origin + 5.0 * Eigen::Vector3d(x, y, z).normalized();
          scan.points_C.push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
        }
      }
    }
    for (int k = 10; k < 60; ++k) {
      const double max_range = 0.01 * k;
      octomap::KeySet free, occupied;
      tree.computeDiscreteUpdate(to_octomap(scan), origin_of(scan), free, occupied, max_range);
      const KeyUpdate ours = compute_key_update(sweep, tree, max_range, 2);
      EXPECT_EQ(ours.free_keys(), sorted(free)) << "max_range " << max_range;
      EXPECT_TRUE(ours.occupied_keys().empty());
    }
  }
}

// Whether every point of `scan` gets coordToKeyChecked's key (as an occupied voxel of the update).
void expect_octomaps_point_keys(const octomap::OcTree& tree, Scan scan) {
  octomap::KeySet expected;
  for (const auto& p : scan.points_C) {
    octomap::OcTreeKey key;
    const bool finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    if (finite && tree.coordToKeyChecked(octomap::point3d(p.x, p.y, p.z), key)) expected.insert(key);
  }
  Sweep sweep;
  sweep.scans.push_back(std::move(scan));
  const KeyUpdate ours = compute_key_update(sweep, tree, 1000.0, 2);
  EXPECT_EQ(ours.occupied_keys(), sorted(expected)) << "resolution " << tree.getResolution();
}

// Keys of random points, of depths in whole millimetres (z × factor often lands next to an integer), of
// points one float step from voxel borders, near the end of the key range (where single precision is
// coarsest) and outside it, at resolutions whose factor is not a power of two or not exactly representable:
// every point gets coordToKeyChecked's key.
TEST(KeyUpdateTest, PointKeysEqualCoordToKeyAtSeveralResolutions) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> coordinate(-2.0f, 2.0f);
  for (const double resolution : {0.02, 0.05, 0.013, 0.1}) {
    const octomap::OcTree tree(resolution);
    Scan near;
    near.origin_C = Eigen::Vector3d(0.011, -0.003, 0.002);
    for (int i = 0; i < 3000; ++i) {
      near.points_C.push_back(pcl::PointXYZ(coordinate(random), coordinate(random), coordinate(random)));
      const float z = static_cast<float>(500 + i) * 0.001f;
      near.points_C.push_back(pcl::PointXYZ(coordinate(random) * z, coordinate(random) * z, z));
    }
    for (int k = -100; k <= 100; ++k) {
      const float border = static_cast<float>(k * resolution);
      for (const float x : {std::nextafter(border, -1e9f), border, std::nextafter(border, 1e9f)}) {
        near.points_C.push_back(pcl::PointXYZ(x, -x, 0.5f * x));
      }
    }
    const float outside = static_cast<float>(40000 * resolution);  // the key range is ±32768 voxels
    for (const float x : {outside, -outside, std::numeric_limits<float>::quiet_NaN()}) {
      near.points_C.push_back(pcl::PointXYZ(x, 0.1f, 0.2f));
      near.points_C.push_back(pcl::PointXYZ(0.1f, 0.2f, x));
    }
    expect_octomaps_point_keys(tree, near);
    Scan far;  // the last 200 voxels of the range, seen from close by
    far.origin_C = Eigen::Vector3d(-32500 * resolution, 0.0, 0.0);
    for (int i = 0; i < 4000; ++i) {
      const float x = static_cast<float>((-32768 + 0.05 * i + 1e-4 * (i % 7)) * resolution);
      far.points_C.push_back(pcl::PointXYZ(x, coordinate(random), coordinate(random)));
    }
    expect_octomaps_point_keys(tree, far);
  }
}

TEST(KeyUpdateTest, BrickIndexRoundTrips) {
  KeyBrick brick;
  brick.base = octomap::OcTreeKey(32768, 32752, 16);
  for (int x = 0; x < 16; x += 5) {
    for (int y = 0; y < 16; y += 3) {
      for (int z = 0; z < 16; z += 7) {
        const octomap::OcTreeKey key(32768 + x, 32752 + y, 16 + z);
        EXPECT_EQ(brick.key(KeyBrick::local_index(key)), key);
      }
    }
  }
  // x is the lowest bit of each triple, z the highest: OctoMap's child order.
  EXPECT_EQ(KeyBrick::local_index(octomap::OcTreeKey(1, 0, 0)), 1);
  EXPECT_EQ(KeyBrick::local_index(octomap::OcTreeKey(0, 1, 0)), 2);
  EXPECT_EQ(KeyBrick::local_index(octomap::OcTreeKey(0, 0, 1)), 4);
  EXPECT_EQ(KeyBrick::local_index(octomap::OcTreeKey(8, 0, 0)), 512);
}

}  // namespace
}  // namespace cellmap
