// SPDX-License-Identifier: Apache-2.0
#include "cellmap/preprocess/point_search.hpp"

#include <gtest/gtest.h>
#include <pcl/search/kdtree.h>

#include <cmath>
#include <initializer_list>
#include <limits>
#include <random>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

// Occupied voxel centres of a 2 cm grid (a crate's three visible faces: many neighbours at exactly equal
// distances, where only the same tree searched the same way gives the same order) and a few scattered points.
Cloud cloud_of(std::initializer_list<pcl::PointXYZ> points) {
  Cloud cloud;
  for (const pcl::PointXYZ& p : points) cloud.push_back(p);
  return cloud;
}

Cloud crate_faces_and_scatter() {
  Cloud cloud;
  for (int i = 0; i < 15; ++i) {
    for (int j = 0; j < 15; ++j) {
      cloud.push_back({0.01f + 0.02f * i, 0.01f + 0.02f * j, 0.31f});             // top
      cloud.push_back({0.01f + 0.02f * i, 0.01f, 0.01f + 0.02f * j});             // front
      if (j > 0) cloud.push_back({0.01f, 0.01f + 0.02f * j, 0.01f + 0.02f * i});  // side
    }
  }
  std::mt19937 random(7);
  std::uniform_real_distribution<float> metres(-0.2f, 0.5f);
  for (int i = 0; i < 60; ++i) cloud.push_back({metres(random), metres(random), metres(random)});
  return cloud;
}

pcl::search::KdTree<pcl::PointXYZ> pcl_tree(const Cloud& cloud, bool sorted, const std::vector<int>* subset) {
  pcl::search::KdTree<pcl::PointXYZ> tree(sorted);
  const Cloud::ConstPtr shared(&cloud, [](const Cloud*) {});
  if (subset) {
    tree.setInputCloud(shared, std::make_shared<const pcl::Indices>(subset->begin(), subset->end()));
  } else {
    tree.setInputCloud(shared);
  }
  return tree;
}

TEST(PointSearch, NearestFindsWhatPclFindsInTheSameOrder) {
  const Cloud cloud = crate_faces_and_scatter();
  const PointSearch ours(cloud);
  auto theirs = pcl_tree(cloud, false, nullptr);
  pcl::Indices found, expected;
  std::vector<float> sq, expected_sq;
  for (const int k : {1, 7, 27, 300}) {
    for (std::size_t i = 0; i < cloud.size(); i += 3) {
      ASSERT_EQ(ours.nearest(cloud[i], k, found, sq),
                theirs.nearestKSearch(cloud[i], k, expected, expected_sq));
      ASSERT_EQ(found, expected) << "k " << k << ", point " << i;
      ASSERT_EQ(sq, expected_sq);
    }
  }
  // The first found is the point itself; the next on a face's interior are its 4 neighbours 2 cm away.
  const pcl::PointXYZ centre_of_top{0.15f, 0.15f, 0.31f};
  ours.nearest(centre_of_top, 5, found, sq);
  EXPECT_NEAR(sq[0], 0.0f, 1e-10f);
  for (int j = 1; j < 5; ++j) EXPECT_NEAR(sq[j], 0.02f * 0.02f, 1e-9f);
}

TEST(PointSearch, NearestClampsKToThePointsThereAre) {
  const Cloud cloud = cloud_of({{0, 0, 0}, {1, 0, 0}, {0, 2, 0}});
  const PointSearch ours(cloud);
  pcl::Indices found;
  std::vector<float> sq;
  EXPECT_EQ(ours.nearest({0.9f, 0, 0}, 10, found, sq), 3);
  EXPECT_EQ(found, (pcl::Indices{1, 0, 2}));
  EXPECT_NEAR(sq[0], 0.01f, 1e-6f);
  EXPECT_EQ(ours.nearest({0, 0, 0}, 0, found, sq), 0);
  EXPECT_TRUE(found.empty());
}

TEST(PointSearch, WithinFindsWhatPclFindsSortedOrNot) {
  const Cloud cloud = crate_faces_and_scatter();
  const PointSearch ours(cloud);
  pcl::Indices found, expected;
  std::vector<float> sq, expected_sq;
  for (const bool sorted : {false, true}) {
    auto theirs = pcl_tree(cloud, sorted, nullptr);
    for (const double radius : {0.019, 0.035, 0.05, 0.2}) {
      for (std::size_t i = 0; i < cloud.size(); i += 5) {
        ASSERT_EQ(ours.within(cloud[i], radius, sorted, found, sq),
                  theirs.radiusSearch(cloud[i], radius, expected, expected_sq));
        ASSERT_EQ(found, expected) << "radius " << radius << ", point " << i << ", sorted " << sorted;
        ASSERT_EQ(sq, expected_sq);
      }
    }
  }
  // Strictly closer than the radius: at 0.019 m a grid point finds only itself.
  EXPECT_EQ(ours.within(cloud[0], 0.019, true, found, sq), 1);
}

TEST(PointSearch, ASubsetAnswersInTheCloudsIndices) {
  const Cloud cloud = crate_faces_and_scatter();
  std::vector<int> subset;
  for (int i = 1; i < static_cast<int>(cloud.size()); i += 4) subset.push_back(i);
  const PointSearch ours(cloud, subset);
  EXPECT_EQ(ours.size(), static_cast<int>(subset.size()));
  auto theirs = pcl_tree(cloud, false, &subset);
  pcl::Indices found, expected;
  std::vector<float> sq, expected_sq;
  for (std::size_t i = 0; i < cloud.size(); i += 2) {
    ours.nearest(cloud[i], 1, found, sq);
    theirs.nearestKSearch(cloud[i], 1, expected, expected_sq);
    ASSERT_EQ(found, expected) << "point " << i;
    ours.within(cloud[i], 0.05, false, found, sq);
    theirs.radiusSearch(cloud[i], 0.05, expected, expected_sq);
    ASSERT_EQ(found, expected) << "point " << i;
  }
  ours.nearest(cloud[1], 1, found, sq);
  EXPECT_EQ(found, pcl::Indices{1});
}

TEST(PointSearch, AnEmptyCloudFindsNothingAndANonFinitePointIsRefused) {
  const PointSearch empty{Cloud{}};
  pcl::Indices found{5};
  std::vector<float> sq{1.0f};
  EXPECT_EQ(empty.nearest({0, 0, 0}, 3, found, sq), 0);
  EXPECT_EQ(empty.within({0, 0, 0}, 1.0, true, found, sq), 0);
  EXPECT_TRUE(found.empty());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(PointSearch(cloud_of({{0, 0, 0}, {nan, 0, 0}})), Error);
}

}  // namespace
}  // namespace cellmap
