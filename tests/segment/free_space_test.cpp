// SPDX-License-Identifier: Apache-2.0
#include "cellmap/segment/free_space.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"
#include "scenes.hpp"

namespace cellmap {
namespace {

std::vector<int> all(const Cloud& cloud) {
  std::vector<int> indices(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) indices[i] = static_cast<int>(i);
  return indices;
}

Box box(const Eigen::Vector3d& center, const Eigen::Vector3d& half) {
  Box b;
  b.center = center;
  b.half_extents = half;
  return b;
}

// A 0.4 m square plate at z = 0.1 (its top and the sides facing the sensor), seen from 1.5 m above.
test::Scene plate() {
  test::Scene scene(Eigen::Vector3f(0.1f, 0.0f, 1.6f));
  scene.add_box({0, 0, 0.09}, {0.2, 0.2, 0.01}, Eigen::Matrix3d::Identity());
  return scene;
}

TEST(SeenFreeSpaceTest, InFrontOfTheSurfaceIsFreeBehindItIsNot) {
  const test::Scene scene = plate();
  const SeenFreeSpace space(scene.points, all(scene.points), scene.viewpoint().cast<double>(), 0.005, 0.01);
  EXPECT_TRUE(space.is_free({0, 0, 0.3}));   // above the plate
  EXPECT_FALSE(space.is_free({0, 0, 0.0}));  // under it: hidden
  EXPECT_FALSE(space.is_free({0.1, 0.1, -0.3}));
  EXPECT_TRUE(space.is_free({0.6, 0, 0.0}));   // beside it: nothing of the plate in that direction
  EXPECT_TRUE(space.is_free({0, 0, 0.13}));    // just above, more than the margin in front
  EXPECT_FALSE(space.is_free({0, 0, 0.105}));  // within the margin of the surface
  // A box above the plate is all free, one under it none, one straddling its edge about half.
  EXPECT_NEAR(space.free_volume(box({0, 0, 0.3}, {0.1, 0.1, 0.1})), 0.008, 1e-9);
  EXPECT_NEAR(space.free_volume(box({0, 0, -0.1}, {0.1, 0.1, 0.1})), 0.0, 1e-9);
  // Under the plate's edge (x = 0.2) the shadow reaches to x ≈ 0.23 at z = −0.1 seen from x = 0.1.
  const double edge = space.free_volume(box({0.2, 0, -0.1}, {0.1, 0.1, 0.05}));
  EXPECT_GT(edge, 0.0008);
  EXPECT_LT(edge, 0.0024);
  EXPECT_THROW(SeenFreeSpace(scene.points, all(scene.points), {0, 0, 0}, 0.0, 0.01), Error);
}

TEST(SeenFreeSpaceTest, ASparseSurfaceStillHidesWhatIsBehindIt) {
  // Points 2 cm apart seen from 1.6 m (0.7° apart) with bins of 0.5°: every direction through the plate is
  // shaded by a point in its bin or a neighbouring one.
  test::Scene scene(Eigen::Vector3f(0.0f, 0.0f, 1.6f));
  scene.add_box({0, 0, 0.09}, {0.2, 0.2, 0.01}, Eigen::Matrix3d::Identity(), 0.02);
  const SeenFreeSpace space(scene.points, all(scene.points), {0, 0, 1.6}, 0.5 * M_PI / 180, 0.01);
  EXPECT_NEAR(space.free_volume(box({0, 0, 0.0}, {0.15, 0.15, 0.05}), 20000), 0.0, 1e-9);
}

}  // namespace
}  // namespace cellmap
