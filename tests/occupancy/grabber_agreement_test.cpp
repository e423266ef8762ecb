// SPDX-License-Identifier: Apache-2.0
// Real frames: our sweep fusion against OctoMap's own insertPointCloud on the grabber sequence.
#include <gtest/gtest.h>

#include <cmath>

#include "cellmap/occupancy/occupancy_map.hpp"
#include "occupancy/grabber_scans.hpp"
#include "support/shared_data.hpp"
#include "tree_agreement.hpp"

namespace cellmap {
namespace {

TEST(GrabberAgreementTest, SameOccupancyAsOctomapInsertPointCloud) {
  CELLMAP_SKIP_WITHOUT_DATA(test::shared_data_dir() / "pcl" / "grabber_sequence");
  const std::vector<Scan> scans = testing::grabber_scans(test::shared_data_dir());
  ASSERT_EQ(scans.size(), 3u);

  const OccupancyConfig config;
  OccupancyMap ours(config);
  octomap::OcTree discretized(config.resolution), exact(config.resolution);
  apply_sensor_model(config, discretized);
  apply_sensor_model(config, exact);
  for (const Scan& scan : scans) {
    Sweep sweep;
    sweep.scans.push_back(scan);
    ours.integrate(sweep);
    octomap::Pointcloud cloud;
    for (const auto& p : scan.points_C.points) {
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) cloud.push_back(p.x, p.y, p.z);
    }
    discretized.insertPointCloud(cloud, octomap::point3d(0, 0, 0), config.max_range, false, true);
    exact.insertPointCloud(cloud, octomap::point3d(0, 0, 0), config.max_range, false, false);
  }
  const TreeAgreement vs_discretized = compare_trees(ours.tree(), discretized);
  const TreeAgreement vs_exact = compare_trees(ours.tree(), exact);
  RecordProperty("agreement_discretized", std::to_string(vs_discretized.fraction()));
  RecordProperty("agreement_exact", std::to_string(vs_exact.fraction()));
  std::printf("agreement vs insertPointCloud: discretized %.5f of %zu voxels, non-discretized %.5f of %zu\n",
              vs_discretized.fraction(), vs_discretized.voxels, vs_exact.fraction(), vs_exact.voxels);
  EXPECT_GT(vs_discretized.voxels, 10000u);
  // The same tree as insertPointCloud(discretize = true), voxel for voxel, to the log-odds.
  EXPECT_EQ(vs_discretized.same, vs_discretized.voxels);
  EXPECT_EQ(vs_discretized.same_log_odds, vs_discretized.voxels);
  // Snapping endpoints to voxel centres bends rays by up to half a voxel; measured 96.9 % here.
  EXPECT_GE(vs_exact.fraction(), 0.95);
  // Occupied voxels do not depend on the ray paths (every endpoint voxel is occupied in both).
  EXPECT_EQ(vs_exact.occupied_a, vs_exact.occupied_b);
  EXPECT_EQ(vs_exact.occupied_both, vs_exact.occupied_a);
}

}  // namespace
}  // namespace cellmap
