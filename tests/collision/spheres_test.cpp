// SPDX-License-Identifier: Apache-2.0
#include "cellmap/collision/spheres.hpp"

#include <gtest/gtest.h>

#include <random>

#include "cellmap/collision/box_distance.hpp"
#include "cellmap/common/error.hpp"

namespace cellmap::collision {
namespace {

using Eigen::Vector3d;

Obb tilted_box() {
  return Obb(Vector3d(0.3, -0.2, 1.0), Vector3d(0.4, 0.1, 0.25),
             Eigen::AngleAxisd(0.7, Vector3d(1, 2, -1).normalized()).toRotationMatrix());
}

TEST(SpheresTest, CoverEveryPointOfTheBox) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Obb box = tilted_box();
  for (int n : {1, 2, 3, 5, 6, 7, 8, 12, 27, 64}) {
    SCOPED_TRACE(n);
    const std::vector<Sphere> spheres = sphere_cover(box, n);
    ASSERT_EQ(spheres.size(), static_cast<std::size_t>(n));
    // Random points, plus the corners (the hardest points to cover).
    for (int i = 0; i < 20000 + 8; ++i) {
      const Vector3d unit = i < 20000 ? Vector3d(u(rng), u(rng), u(rng))
                                      : Vector3d((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
      const Vector3d p = box.center + box.rotation * unit.cwiseProduct(box.half_extents);
      bool covered = false;
      for (const Sphere& s : spheres) covered = covered || (p - s.center).norm() <= s.radius + 1e-12;
      ASSERT_TRUE(covered) << p.transpose();
    }
  }
}

TEST(SpheresTest, PaperCountsHaveTheExpectedShape) {
  const Obb cube(Vector3d::Zero(), Vector3d(0.5, 0.5, 0.5));
  EXPECT_NEAR(sphere_cover(cube, 1)[0].radius, std::sqrt(0.75), 1e-15);
  // N = 2 halves the longest axis: radius sqrt(0.25^2 + 0.5^2 + 0.5^2).
  const Obb bar(Vector3d::Zero(), Vector3d(0.5, 1.0, 0.5));
  const auto two = sphere_cover(bar, 2);
  EXPECT_NEAR(two[0].radius, std::sqrt(0.25 + 0.25 + 0.25), 1e-15);
  EXPECT_NEAR(std::abs(two[0].center.y()), 0.5, 1e-15);
  // N = 6 on a cube: 3 x 2 x 1 cells, radius sqrt((1/6)^2 + (1/4)^2 + (1/2)^2).
  EXPECT_NEAR(sphere_cover(cube, 6)[0].radius, std::sqrt(1.0 / 36 + 1.0 / 16 + 0.25), 1e-15);
  EXPECT_THROW((void)sphere_cover(cube, 0), Error);
}

TEST(SpheresTest, NonCollisionConditionWithMargin) {
  const Sphere a{Vector3d::Zero(), 0.5};
  const Sphere b{Vector3d(1.2, 0, 0), 0.5};
  EXPECT_NEAR(sphere_distance(a, b), 0.2, 1e-15);
  EXPECT_TRUE(spheres_clear(a, b, 0.19));
  EXPECT_TRUE(spheres_clear(a, b, 0.2));
  EXPECT_FALSE(spheres_clear(a, b, 0.21));
}

TEST(SpheresTest, SphereMethodIsConservative) {
  // The sphere distance of two covered boxes never exceeds their true distance, and overlapping boxes always
  // have overlapping spheres (depths are not comparable: spheres measure their own penetration).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> h(0.05, 0.5);
  for (int i = 0; i < 2000; ++i) {
    const Obb a(Vector3d(u(rng), u(rng), u(rng)), Vector3d(h(rng), h(rng), h(rng)),
                Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix());
    const Obb b(Vector3d(u(rng), u(rng), u(rng)) * 3, Vector3d(h(rng), h(rng), h(rng)),
                Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix());
    const double exact = signed_distance(a, b).distance;
    for (int n : {1, 2, 6}) {
      const double spheres = sphere_set_distance(sphere_cover(a, n), sphere_cover(b, n));
      EXPECT_LE(spheres, std::max(exact, 0.0) + 1e-12);
    }
  }
}

TEST(SpheresTest, SphereBoxDistance) {
  const Obb box(Vector3d::Zero(), Vector3d(1, 1, 1));
  EXPECT_NEAR(sphere_box_distance({Vector3d(3, 0, 0), 0.5}, box), 1.5, 1e-15);
  EXPECT_NEAR(sphere_box_distance({Vector3d(2, 2, 1), 0.1}, box), std::sqrt(2.0) - 0.1, 1e-15);
  EXPECT_NEAR(sphere_box_distance({Vector3d(0.5, 0, 0), 0.25}, box), -0.75, 1e-15);
}

}  // namespace
}  // namespace cellmap::collision
