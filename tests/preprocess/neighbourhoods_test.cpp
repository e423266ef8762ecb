// SPDX-License-Identifier: Apache-2.0
#include "cellmap/preprocess/neighbourhoods.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

// A 20 x 20 grid of 1 cm spacing in the plane z = 1 (the sensor looks along +z from the origin).
Cloud plane_grid() {
  Cloud cloud;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) cloud.push_back({0.01f * i, 0.01f * j, 1.0f});
  }
  return cloud;
}

TEST(Neighbourhoods, MeanDistanceOnAGridIsEquation1) {
  const Cloud cloud = plane_grid();
  const Neighbourhoods nb = compute_neighbourhoods(cloud, 4, false);
  // An interior point's 4 nearest neighbours are the 4 grid neighbours at 1 cm.
  const int interior = 10 * 20 + 10;
  EXPECT_NEAR(nb.mean_distance[interior], 0.01f, 1e-6f);
  // A corner has 2 neighbours at 1 cm, 1 at sqrt(2) cm and 1 at 2 cm.
  EXPECT_NEAR(nb.mean_distance[0], (0.01f + 0.01f + 0.01f * std::sqrt(2.0f) + 0.02f) / 4.0f, 1e-6f);
  for (int j = 0; j < 4; ++j) EXPECT_NE(nb.neighbour(interior, j), interior);
  EXPECT_TRUE(nb.normals.empty());
}

TEST(Neighbourhoods, PlaneNormalsFaceTheViewpointWithZeroCurvature) {
  const Cloud cloud = plane_grid();
  const Neighbourhoods nb = compute_neighbourhoods(cloud, 8, true, Eigen::Vector3f::Zero());
  for (int i = 0; i < nb.size(); ++i) {
    EXPECT_NEAR(nb.normals[i].z(), -1.0f, 1e-4f);  // toward the sensor at the origin
    EXPECT_NEAR(nb.curvature[i], 0.0f, 1e-5f);
  }
  const Neighbourhoods flipped = compute_neighbourhoods(cloud, 8, true, Eigen::Vector3f(0, 0, 5));
  EXPECT_NEAR(flipped.normals[0].z(), 1.0f, 1e-4f);
}

TEST(Neighbourhoods, CurvatureIsHighAtAnEdge) {
  // Two perpendicular half planes meeting at x = 0: points near the edge see both.
  Cloud cloud;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      cloud.push_back({0.01f * i, 0.01f * j, 1.0f});
      if (i > 0) cloud.push_back({0.0f, 0.01f * j, 1.0f - 0.01f * i});
    }
  }
  const Neighbourhoods nb = compute_neighbourhoods(cloud, 12, true);
  const auto index_of = [&](float x, float y, float z) {
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if ((cloud[i].getVector3fMap() - Eigen::Vector3f(x, y, z)).norm() < 1e-5f) return static_cast<int>(i);
    }
    return -1;
  };
  const int edge = index_of(0.0f, 0.1f, 1.0f);
  const int flat = index_of(0.15f, 0.1f, 1.0f);
  ASSERT_GE(edge, 0);
  ASSERT_GE(flat, 0);
  EXPECT_GT(nb.curvature[edge], 0.05f);
  EXPECT_LT(nb.curvature[flat], 1e-4f);
}

TEST(Neighbourhoods, SubsetRenumbersAndDropsRemovedNeighbours) {
  const Cloud cloud = plane_grid();
  const Neighbourhoods all = compute_neighbourhoods(cloud, 8, true);
  std::vector<int> kept;
  for (int i = 0; i < all.size(); ++i) {
    if (i % 2 == 0) kept.push_back(i);
  }
  const Neighbourhoods sub = subset_neighbourhoods(all, kept);
  ASSERT_EQ(sub.size(), static_cast<int>(kept.size()));
  for (int n = 0; n < sub.size(); ++n) {
    EXPECT_EQ(sub.mean_distance[n], all.mean_distance[kept[n]]);
    float last = 0.0f;
    for (int j = 0; j < sub.k && sub.neighbour(n, j) >= 0; ++j) {
      const int original = kept[sub.neighbour(n, j)];
      const float d = (cloud[original].getVector3fMap() - cloud[kept[n]].getVector3fMap()).squaredNorm();
      EXPECT_NEAR(sub.sq_distance(n, j), d, 1e-9f);
      EXPECT_GE(sub.sq_distance(n, j), last);
      last = sub.sq_distance(n, j);
    }
  }
  EXPECT_THROW((void)subset_neighbourhoods(all, {3, 1}), Error);
}

TEST(Neighbourhoods, RejectsBadInput) {
  EXPECT_THROW((void)compute_neighbourhoods(plane_grid(), 0, false), Error);
  Cloud cloud = plane_grid();
  cloud.push_back({NAN, 0, 0});
  EXPECT_THROW((void)compute_neighbourhoods(cloud, 4, false), Error);
}

}  // namespace
}  // namespace cellmap
