// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/ray_cast.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace cellmap::sim {
namespace {

const Eigen::Vector3d kX = Eigen::Vector3d::UnitX();
const Eigen::Vector3d kZ = Eigen::Vector3d::UnitZ();

TEST(IntersectTest, BoxKnownAnswers) {
  const BoxShape box{Eigen::Vector3d(1, 2, 3)};
  EXPECT_DOUBLE_EQ(*intersect(box, {-5, 0, 0}, kX), 4.0);
  EXPECT_DOUBLE_EQ(*intersect(box, {0, 0, 10}, -kZ), 7.0);
  EXPECT_DOUBLE_EQ(*intersect(box, {0, 0, 0}, kX), 0.0);  // inside: blinded at once
  EXPECT_FALSE(intersect(box, {-5, 2.5, 0}, kX));         // passes beside
  EXPECT_FALSE(intersect(box, {5, 0, 0}, kX));            // box behind the ray
  // Diagonal through the corner region: from (-3, -3, 0) along (1, 1, 0)/√2 enters at x = -1 (y = -1).
  EXPECT_NEAR(*intersect(box, {-3, -3, 0}, Eigen::Vector3d(1, 1, 0).normalized()), 2 * std::sqrt(2.0), 1e-12);
}

TEST(IntersectTest, CylinderKnownAnswers) {
  const CylinderShape cylinder{0.5, 1.0};
  EXPECT_DOUBLE_EQ(*intersect(cylinder, {-3, 0, 0}, kX), 2.5);  // side
  EXPECT_DOUBLE_EQ(*intersect(cylinder, {0, 0, 4}, -kZ), 3.0);  // cap, along the axis
  EXPECT_DOUBLE_EQ(*intersect(cylinder, {0.3, 0, 4}, -kZ), 3.0);
  EXPECT_FALSE(intersect(cylinder, {0.6, 0, 4}, -kZ));  // parallel, outside the radius
  EXPECT_FALSE(intersect(cylinder, {-3, 0, 1.2}, kX));  // above the top cap
  // Grazing the rim: (−3, 0.3, 0) along x enters at x = −0.4.
  EXPECT_NEAR(*intersect(cylinder, {-3, 0.3, 0}, kX), 2.6, 1e-12);
  // Through the top rim at 45°: from (-2, 0, 2.5) towards (0, 0, 0.5)... enters the cap at z = 1, x = -0.5.
  EXPECT_NEAR(*intersect(cylinder, {-2, 0, 2.5}, Eigen::Vector3d(1, 0, -1).normalized()),
              1.5 * std::sqrt(2.0), 1e-12);
}

TEST(IntersectTest, SphereKnownAnswers) {
  const SphereShape sphere{2.0};
  EXPECT_DOUBLE_EQ(*intersect(sphere, {0, 0, 10}, -kZ), 8.0);
  EXPECT_DOUBLE_EQ(*intersect(sphere, {0, 0, 0}, kX), 0.0);
  EXPECT_NEAR(*intersect(sphere, {-5, 1, 0}, kX), 5 - std::sqrt(3.0), 1e-12);
  EXPECT_FALSE(intersect(sphere, {-5, 2.01, 0}, kX));
}

TEST(SceneCasterTest, FindsTheNearestObstacleInRotatedFrames) {
  Obstacle near_box{"near", BoxShape{Eigen::Vector3d(0.5, 0.5, 0.5)}, Eigen::Isometry3d::Identity()};
  near_box.X_CO.translation() = Eigen::Vector3d(3, 0, 0);
  near_box.X_CO.linear() = Eigen::AngleAxisd(M_PI / 4, kZ).toRotationMatrix();
  Obstacle far_sphere{"far", SphereShape{1.0}, Eigen::Isometry3d::Identity()};
  far_sphere.X_CO.translation() = Eigen::Vector3d(6, 0, 0);
  const SceneCaster caster({far_sphere, near_box});
  const RayHit hit = caster.cast(Eigen::Vector3d::Zero(), kX, 100.0);
  EXPECT_EQ(hit.obstacle, 1);
  EXPECT_NEAR(hit.t, 3 - 0.5 * std::sqrt(2.0), 1e-12);  // the turned box's corner points at the origin
  EXPECT_EQ(caster.cast(Eigen::Vector3d::Zero(), kX, 2.0).obstacle, -1);  // beyond t_max
  EXPECT_EQ(caster.cast(Eigen::Vector3d::Zero(), -kX, 100.0).obstacle, -1);
}

TEST(SceneCasterTest, ConeCullingNeverDropsAHit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-2.0, 2.0), size(0.05, 0.4), unit(-1.0, 1.0);
  std::vector<Obstacle> obstacles;
  for (int i = 0; i < 30; ++i) {
    Obstacle o;
    o.name = "o" + std::to_string(i);
    if (i % 3 == 0) o.shape = BoxShape{Eigen::Vector3d(size(rng), size(rng), size(rng))};
    if (i % 3 == 1) o.shape = CylinderShape{size(rng), size(rng)};
    if (i % 3 == 2) o.shape = SphereShape{size(rng)};
    o.X_CO.translation() = Eigen::Vector3d(pos(rng), pos(rng), pos(rng) + 4.0);
    o.X_CO.linear() =
        Eigen::Quaterniond(unit(rng), unit(rng), unit(rng), unit(rng)).normalized().toRotationMatrix();
    obstacles.push_back(o);
  }
  const SceneCaster caster(obstacles);
  const Eigen::Vector3d apex = Eigen::Vector3d::Zero();
  const Eigen::Vector3d axis = Eigen::Vector3d(0.1, -0.2, 1).normalized();
  const double half_angle = 0.3;
  const std::vector<SceneCaster::Candidate> candidates = caster.candidates(apex, axis, half_angle);
  EXPECT_LT(candidates.size(), obstacles.size());  // the cone does cull
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    // A random direction inside the cone.
    Eigen::Vector3d d;
    do {
      d = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    } while (std::acos(d.dot(axis)) > half_angle);
    const RayHit all = caster.cast(apex, d, 50.0);
    const RayHit culled = caster.cast(apex, d, 50.0, &candidates);
    EXPECT_EQ(all.obstacle, culled.obstacle);
    EXPECT_EQ(all.t, culled.t);
    hits += all.obstacle >= 0;
  }
  EXPECT_GT(hits, 100);
}

TEST(ExitDistanceTest, LeavesTheBoundsOnTheNearestFace) {
  const Region bounds{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 2, 3)};
  EXPECT_DOUBLE_EQ(exit_distance(bounds, {1, 1, 1}, kX), 3.0);
  EXPECT_DOUBLE_EQ(exit_distance(bounds, {1, 1, 1}, -kZ), 1.0);
  EXPECT_DOUBLE_EQ(exit_distance(bounds, {5, 1, 1}, -kX), 0.0);  // starts outside
}

}  // namespace
}  // namespace cellmap::sim
