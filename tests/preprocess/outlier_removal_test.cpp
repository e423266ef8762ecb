// SPDX-License-Identifier: Apache-2.0
#include "cellmap/preprocess/outlier_removal.hpp"

#include <gtest/gtest.h>
#include <pcl/filters/statistical_outlier_removal.h>

#include <random>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

// 30 x 30 grid, 1 cm spacing; its mean 8-neighbour distances lie in [0.01207, 0.01839] m.
Cloud grid() {
  Cloud cloud;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) cloud.push_back({0.01f * i, 0.01f * j, 0.0f});
  }
  return cloud;
}

std::vector<int> range(int from, int to) {
  std::vector<int> r;
  for (int i = from; i < to; ++i) r.push_back(i);
  return r;
}

TEST(OutlierRemoval, RemovesExactlyThePlantedSparseOutliers) {
  Cloud cloud = grid();
  // Four isolated points, 0.2 m and more from anything: mean distance ~0.21 m.
  cloud.push_back({0.5f, 0.15f, 0.0f});
  cloud.push_back({-0.2f, 0.1f, 0.05f});
  cloud.push_back({0.15f, 0.5f, 0.0f});
  cloud.push_back({0.1f, -0.2f, 0.1f});
  const Neighbourhoods nb = compute_neighbourhoods(cloud, 8, false);
  for (OutlierMode mode : {OutlierMode::kTwoSided, OutlierMode::kOneSided}) {
    const OutlierResult result = remove_outliers(nb, 2.0, mode);
    EXPECT_EQ(result.kept, range(0, 900));
    EXPECT_EQ(result.removed_sparse, 4u);
    EXPECT_EQ(result.removed_dense, 0u);
  }
}

TEST(OutlierRemoval, TwoSidedAlsoRemovesThePlantedDenseClumps) {
  Cloud cloud = grid();
  // Two clumps of 9 coincident points: their 8 neighbours are at distance 0.
  for (int i = 0; i < 9; ++i) cloud.push_back({0.15f, 0.15f, 0.3f});
  for (int i = 0; i < 9; ++i) cloud.push_back({0.05f, 0.25f, -0.3f});
  const Neighbourhoods nb = compute_neighbourhoods(cloud, 8, false);
  // mu = 0.01220, sigma = 0.00198: u = 3.5 keeps the grid's corners (0.0184 < 0.0191) and drops d = 0.
  const OutlierResult two = remove_outliers(nb, 3.5, OutlierMode::kTwoSided);
  EXPECT_EQ(two.kept, range(0, 900));
  EXPECT_EQ(two.removed_dense, 18u);
  EXPECT_NEAR(two.mean, 0.012196, 1e-5);
  EXPECT_NEAR(two.stddev, 0.0019834, 1e-6);
  const OutlierResult one = remove_outliers(nb, 3.5, OutlierMode::kOneSided);
  EXPECT_EQ(one.kept, range(0, 918));
  const OutlierResult off = remove_outliers(nb, 3.5, OutlierMode::kOff);
  EXPECT_EQ(off.kept.size(), 918u);
}

TEST(OutlierRemoval, OneSidedAgreesExactlyWithPclsFilter) {
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.002f);
  std::uniform_real_distribution<float> uniform(-0.5f, 0.5f);
  Cloud::Ptr cloud(new Cloud);
  for (int i = 0; i < 4000; ++i) cloud->push_back({uniform(rng), uniform(rng), 1.0f + noise(rng)});
  for (int i = 0; i < 200; ++i) cloud->push_back({uniform(rng), uniform(rng), 1.0f + 0.3f * uniform(rng)});
  for (double u : {0.5, 1.0, 2.0}) {
    for (int k : {5, 20}) {
      pcl::StatisticalOutlierRemoval<pcl::PointXYZ> pcl_filter;
      pcl_filter.setInputCloud(cloud);
      pcl_filter.setMeanK(k);
      pcl_filter.setStddevMulThresh(u);
      pcl::Indices pcl_kept;
      pcl_filter.filter(pcl_kept);
      const OutlierResult ours =
          remove_outliers(compute_neighbourhoods(*cloud, k, false), u, OutlierMode::kOneSided);
      EXPECT_EQ(ours.kept, std::vector<int>(pcl_kept.begin(), pcl_kept.end())) << "u " << u << " k " << k;
      EXPECT_GT(ours.removed_sparse, 0u);
    }
  }
}

TEST(OutlierRemoval, RejectsNegativeMultiplier) {
  const Neighbourhoods nb = compute_neighbourhoods(grid(), 4, false);
  EXPECT_THROW((void)remove_outliers(nb, -1.0, OutlierMode::kTwoSided), Error);
}

}  // namespace
}  // namespace cellmap
