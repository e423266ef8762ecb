// SPDX-License-Identifier: Apache-2.0
#include "cellmap/frame/frame.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

DepthImage small_image() {
  DepthImage image;
  image.intrinsics.width = 4;
  image.intrinsics.height = 2;
  image.intrinsics.fx = 2.0;
  image.intrinsics.fy = 4.0;
  image.intrinsics.cx = 1.5;
  image.intrinsics.cy = 0.5;
  image.depth = {1000, 0, 2000, 3000, 500, 20000, 1500, 1000};
  return image;
}

TEST(DepthToPointsTest, BackProjectsThePinholeModel) {
  const Cloud cloud = depth_to_points(small_image());
  // Pixel (1,0) has no return and (1,1) is beyond the default 10 m range: 6 valid points.
  ASSERT_EQ(cloud.size(), 6u);
  // Pixel (u=0, v=0), z = 1 m: x = (0 - 1.5) * 1 / 2, y = (0 - 0.5) * 1 / 4.
  EXPECT_FLOAT_EQ(cloud[0].x, -0.75f);
  EXPECT_FLOAT_EQ(cloud[0].y, -0.125f);
  EXPECT_FLOAT_EQ(cloud[0].z, 1.0f);
  // Pixel (u=3, v=1), z = 1 m.
  EXPECT_FLOAT_EQ(cloud[5].x, 0.75f);
  EXPECT_FLOAT_EQ(cloud[5].y, 0.125f);
  EXPECT_FLOAT_EQ(cloud[5].z, 1.0f);
}

TEST(DepthToPointsTest, OrganizedKeepsTheGridWithNaN) {
  const Cloud cloud = depth_to_points(small_image(), true);
  EXPECT_EQ(cloud.width, 4u);
  EXPECT_EQ(cloud.height, 2u);
  EXPECT_TRUE(std::isnan(cloud.at(1, 0).z));
  EXPECT_TRUE(std::isnan(cloud.at(1, 1).z));
  EXPECT_FLOAT_EQ(cloud.at(2, 0).z, 2.0f);
}

// A 9 × 3 image: a wall at 1.000 m (columns 0–3) before a wall at 2.000 m (columns 5–8), and between them
// column 4 at 1.500 m, where a time-of-flight pixel mixing both walls lands; the near wall is tilted so its
// neighbours differ by 1 % of their depth.
DepthImage depth_edge() {
  DepthImage image;
  image.intrinsics.width = 9;
  image.intrinsics.height = 3;
  image.intrinsics.fx = image.intrinsics.fy = 10.0;
  image.intrinsics.cx = 4.0;
  image.intrinsics.cy = 1.0;
  for (int v = 0; v < 3; ++v) {
    for (const std::uint16_t z : {1000, 1010, 1020, 1030, 1500, 2000, 2000, 2000, 2000})
      image.depth.push_back(z);
  }
  return image;
}

TEST(DepthToPointsTest, FlyingPixelFilterDropsWhatLiesBehindADepthEdgeAndKeepsSurfaces) {
  DepthImage image = depth_edge();
  EXPECT_EQ(depth_to_points(image).size(), 27u) << "off by default";
  image.intrinsics.max_depth_jump = 0.02;
  const Cloud organized = depth_to_points(image, true);
  for (int v = 0; v < 3; ++v) {
    for (int u = 0; u < 9; ++u) {
      // Dropped: the flying column and the far wall's rim behind it (one pixel); the near wall's rim stays.
      EXPECT_EQ(std::isnan(organized.at(u, v).z), u == 4 || u == 5) << u << "," << v;
    }
  }
  EXPECT_EQ(depth_to_points(image).size(), 21u);
  // A pixel without a return is no neighbour: a hole does not drop the pixels around it.
  image.depth[9 + 1] = 0;
  EXPECT_EQ(depth_to_points(image).size(), 20u);
  image.intrinsics.max_depth_jump = -0.1;
  EXPECT_THROW((void)depth_to_points(image), Error);
}

// A width × height image, focal length `f`, its principal point at the centre, whose depth at (u, v) is
// depth(u, v, r) for a pseudo-random r (a linear congruential sequence from `seed`, row by row).
template <class Depth>
DepthImage random_image(int width, int height, double f, double max_depth_jump, std::uint32_t seed,
                        const Depth& depth) {
  DepthImage image;
  image.intrinsics.width = width;
  image.intrinsics.height = height;
  image.intrinsics.fx = image.intrinsics.fy = f;
  image.intrinsics.cx = (width - 1) / 2.0;
  image.intrinsics.cy = (height - 1) / 2.0;
  image.intrinsics.max_depth_jump = max_depth_jump;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      seed = seed * 1664525u + 1013904223u;
      image.depth.push_back(depth(u, v, seed >> 8));
    }
  }
  return image;
}

// The filter's definition, pixel by pixel: dropped when a valid 8-neighbour inside the image is nearer by
// more than max_depth_jump of the pixel's depth.
bool behind_an_edge(const DepthImage& image, int u, int v) {
  const PinholeIntrinsics& k = image.intrinsics;
  const auto depth = [&](int x, int y) {
    const double d = image.depth[std::size_t(y * k.width + x)] * k.depth_scale;
    return d >= k.min_range && d <= k.max_range && image.depth[std::size_t(y * k.width + x)] != 0 ? d : 0.0;
  };
  const double z = depth(u, v);
  for (int y = std::max(0, v - 1); y <= std::min(k.height - 1, v + 1); ++y) {
    for (int x = std::max(0, u - 1); x <= std::min(k.width - 1, u + 1); ++x) {
      const double near = depth(x, y);
      if ((x != u || y != v) && near > 0 && z - near > k.max_depth_jump * z) return true;
    }
  }
  return false;
}

// Noisy surfaces at two depths with holes, edges on every side and at the image's borders: the filter
// drops exactly the pixels its definition drops.
TEST(DepthToPointsTest, FlyingPixelFilterDropsExactlyWhatItsDefinitionDrops) {
  const DepthImage image = random_image(37, 23, 30.0, 0.02, 7, [](int u, int v, std::uint32_t r) {
    const bool near = (u / 5 + v / 4) % 2 == 0;
    return r % 13 == 0 ? 0 : std::uint16_t((near ? 1000 : 1800) + r % 41);
  });
  const Cloud organized = depth_to_points(image, true);
  std::size_t dropped = 0;
  for (int v = 0; v < image.intrinsics.height; ++v) {
    for (int u = 0; u < image.intrinsics.width; ++u) {
      const bool none = image.depth[std::size_t(v * image.intrinsics.width + u)] == 0;
      const bool expected = none || behind_an_edge(image, u, v);
      EXPECT_EQ(std::isnan(organized.at(u, v).z), expected) << u << "," << v;
      dropped += expected && !none ? 1 : 0;
    }
  }
  EXPECT_GT(dropped, 100u) << "too few edges to test";
}

// One row: each depth becomes the mean of its neighbours within the radius and within max_depth_jump of it.
TEST(DepthToPointsTest, SmoothingAveragesNeighboursWithinTheJumpOnly) {
  DepthImage image;
  image.intrinsics.width = 6;
  image.intrinsics.height = 1;
  image.intrinsics.fx = image.intrinsics.fy = 10.0;
  image.intrinsics.max_depth_jump = 0.05;
  image.intrinsics.smoothing_radius = 1;
  image.depth = {1000, 1010, 1020, 3000, 3000, 0};
  const Cloud organized = depth_to_points(image, true);  // one row: indexed as a list
  EXPECT_FLOAT_EQ(organized[0].z, 1.005f);
  EXPECT_FLOAT_EQ(organized[1].z, 1.010f);
  EXPECT_FLOAT_EQ(organized[2].z, 1.015f) << "the pixel across the edge is no neighbour";
  EXPECT_TRUE(std::isnan(organized[3].z)) << "behind the edge: the flying-pixel filter's";
  EXPECT_FLOAT_EQ(organized[4].z, 3.000f);
  EXPECT_TRUE(std::isnan(organized[5].z)) << "a hole stays a hole";
  image.intrinsics.max_depth_jump = 0;
  EXPECT_FLOAT_EQ(depth_to_points(image, true)[0].z, 1.0f) << "no smoothing without the edge limit";
}

// Two walls (1 m and 2 m) scattered by ±20 mm: smoothing with radius 2 leaves under a third of the scatter on
// a wall and none of one wall's depths in the other's.
TEST(DepthToPointsTest, SmoothingShrinksAFlatSurfacesScatterAndKeepsItsEdge) {
  DepthImage image = random_image(60, 40, 50.0, 0.05, 11, [](int u, int, std::uint32_t r) {
    return std::uint16_t((u < 30 ? 1000 : 2000) + r % 41 - 20);
  });
  const auto scatter = [](const Cloud& organized) {
    double sum = 0, sq = 0;
    int n = 0;
    for (int v = 5; v < 35; ++v) {
      for (int u = 5; u < 25; ++u) {
        const double z = organized.at(u, v).z;
        sum += z, sq += z * z, ++n;
      }
    }
    return std::sqrt(sq / n - (sum / n) * (sum / n));
  };
  const double raw = scatter(depth_to_points(image, true));
  image.intrinsics.smoothing_radius = 2;
  const Cloud smoothed = depth_to_points(image, true);
  EXPECT_LT(scatter(smoothed), 0.3 * raw) << raw;
  for (int v = 0; v < 40; ++v) {
    for (int u = 0; u < 60; ++u) {
      const float z = smoothed.at(u, v).z;
      if (std::isnan(z)) continue;  // the far wall's rim, behind the edge
      EXPECT_NEAR(z, u < 30 ? 1.0 : 2.0, 0.021) << u << "," << v;
    }
  }
}

TEST(DepthToPointsTest, RejectsSizeMismatchAndBadIntrinsics) {
  DepthImage image = small_image();
  image.depth.pop_back();
  EXPECT_THROW((void)depth_to_points(image), Error);
  image = small_image();
  image.intrinsics.smoothing_radius = kMaxSmoothingRadius + 1;
  EXPECT_THROW((void)depth_to_points(image), Error);
  image = small_image();
  image.intrinsics.fx = 0;
  EXPECT_THROW((void)depth_to_points(image), Error);
}

}  // namespace
}  // namespace cellmap
