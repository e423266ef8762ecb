// SPDX-License-Identifier: Apache-2.0
#include "cellmap/segment/region_growing.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "scenes.hpp"

namespace cellmap {
namespace {

// The segment holding most of the points for which `pick` is true, and how many such points it holds.
template <typename Pick>
std::pair<int, int> majority(const Segments& s, const Cloud& cloud, Pick pick) {
  std::map<int, int> count;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (pick(cloud[i].getVector3fMap())) ++count[s.label[i]];
  }
  std::pair<int, int> best{-1, 0};
  for (const auto& [label, n] : count) {
    if (n > best.second) best = {label, n};
  }
  return best;
}

TEST(RegionGrowing, SeparatesTheFacesOfABoxAtTheir90DegreeEdges) {
  test::Scene scene(Eigen::Vector3f(0.3f, -0.4f, 0.6f));
  scene.add_box({0, 0, 0.05}, {0.05, 0.05, 0.05}, Eigen::Matrix3d::Identity());
  const Neighbourhoods nb = compute_neighbourhoods(scene.points, 20, true, scene.viewpoint());
  const Segments s = grow_regions(nb, RegionGrowingParams{});
  // Visible faces: top (z = 0.1), front (y = -0.05), right (x = 0.05). Their interiors (1.5 cm from the
  // edges) must each lie in one region, three different ones.
  const auto top = majority(s, scene.points, [](const Eigen::Vector3f& p) {
    return p.z() > 0.099f && std::abs(p.x()) < 0.035f && std::abs(p.y()) < 0.035f;
  });
  const auto front = majority(s, scene.points, [](const Eigen::Vector3f& p) {
    return p.y() < -0.049f && std::abs(p.x()) < 0.035f && std::abs(p.z() - 0.05f) < 0.035f;
  });
  const auto right = majority(s, scene.points, [](const Eigen::Vector3f& p) {
    return p.x() > 0.049f && std::abs(p.y()) < 0.035f && std::abs(p.z() - 0.05f) < 0.035f;
  });
  const int interior = 13 * 13;  // |x| < 0.035 on the 5 mm grid: 13 points per side
  EXPECT_EQ(top.second, interior);
  EXPECT_EQ(front.second, interior);
  EXPECT_EQ(right.second, interior);
  EXPECT_GE(top.first, 0);
  EXPECT_EQ((std::set<int>{top.first, front.first, right.first}).size(), 3u);
}

TEST(RegionGrowing, NeverBridgesAGapWiderThanDth) {
  // Two coplanar 10 x 10 cm patches 2 cm apart.
  test::Scene scene(Eigen::Vector3f(0, 0, 1));
  scene.add_box({0, 0, 0}, {0.05, 0.05, 0}, Eigen::Matrix3d::Identity());
  scene.add_box({0.12, 0, 0}, {0.05, 0.05, 0}, Eigen::Matrix3d::Identity());
  const Neighbourhoods nb = compute_neighbourhoods(scene.points, 30, true, scene.viewpoint());
  RegionGrowingParams params;
  params.gap = 0.01;
  EXPECT_EQ(grow_regions(nb, params).count, 2);
  params.gap = 0.03;
  EXPECT_EQ(grow_regions(nb, params).count, 1);
}

TEST(RegionGrowing, NormalAngleThresholdSplitsABend) {
  // Two flat strips meeting at a 20° bend along x = 0.
  test::Scene scene(Eigen::Vector3f(0, 0, 1));
  for (int a = 0; a <= 40; ++a) {
    for (int b = 0; b <= 20; ++b) {
      const float u = 0.005f * a, y = 0.005f * b;
      scene.add(Eigen::Vector3f(-u, y, 0.0f), 1);
      if (a > 0) scene.add(Eigen::Vector3f(u * std::cos(0.349f), y, u * std::sin(0.349f)), 2);
    }
  }
  const Neighbourhoods nb = compute_neighbourhoods(scene.points, 20, true, scene.viewpoint());
  RegionGrowingParams params;
  params.max_curvature = 1.0 / 3.0;  // let every point grow on: only the angle decides here
  params.max_angle = 0.07;
  EXPECT_GE(grow_regions(nb, params).count, 2);
  params.max_angle = 0.5;
  EXPECT_EQ(grow_regions(nb, params).count, 1);
}

TEST(Leftovers, EveryPointIsAttachedOrCountedAsIsolated) {
  test::Scene scene(Eigen::Vector3f(0, 0, 1));
  scene.add_box({0, 0, 0}, {0.05, 0.05, 0}, Eigen::Matrix3d::Identity());
  scene.add(Eigen::Vector3f(0.5f, 0.5f, 0.0f), 9);  // isolated point
  for (int i = 0; i < 5; ++i) scene.add(Eigen::Vector3f(-0.5f + 0.004f * i, 0.5f, 0.0f), 8);  // small group
  const Neighbourhoods nb = compute_neighbourhoods(scene.points, 10, true, scene.viewpoint());
  Segments s;
  s.label.assign(scene.points.size(), -1);
  for (int i = 0; i < 50; ++i) s.label[i] = 0;  // one seed segment on the patch
  s.count = 1;
  const LeftoverStats stats = cover_leftovers(scene.points, nb, s, 0.01, 3);
  EXPECT_EQ(stats.isolated, 1u);
  EXPECT_EQ(stats.own_segments, 1u);
  EXPECT_EQ(stats.in_own_segments, 5u);
  EXPECT_EQ(stats.attached, scene.points.size() - 50 - 6);
  EXPECT_EQ(s.unlabelled(), 1u);
  EXPECT_EQ(s.label.back(), 1);
}

}  // namespace
}  // namespace cellmap
