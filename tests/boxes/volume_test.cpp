// SPDX-License-Identifier: Apache-2.0
#include "cellmap/boxes/volume.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace cellmap {
namespace {

Box make_box(const Eigen::Vector3d& center, const Eigen::Vector3d& half,
             const Eigen::Quaterniond& rotation = Eigen::Quaterniond::Identity()) {
  Box box;
  box.center = center;
  box.half_extents = half;
  box.rotation = rotation;
  return box;
}

TEST(BoxVolumeTest, KnownOverlaps) {
  const Box cube = make_box({0, 0, 0}, {1, 1, 1});
  EXPECT_NEAR(intersection_volume(cube, cube), 8.0, 1e-12);
  EXPECT_NEAR(volume_iou(cube, cube), 1.0, 1e-12);
  // Shifted by half an edge: half the cube in common, IoU 4 / 12.
  const Box shifted = make_box({1, 0, 0}, {1, 1, 1});
  EXPECT_NEAR(intersection_volume(cube, shifted), 4.0, 1e-12);
  EXPECT_NEAR(volume_iou(cube, shifted), 1.0 / 3.0, 1e-12);
  // Turned 45° about z: a regular octagon prism, area 8√2 − 8, height 2.
  const Box turned = make_box({0, 0, 0}, {1, 1, 1},
                              Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ())));
  EXPECT_NEAR(intersection_volume(cube, turned), 2 * (8 * std::sqrt(2.0) - 8), 1e-12);
  EXPECT_NEAR(intersection_volume(turned, cube), 2 * (8 * std::sqrt(2.0) - 8), 1e-12);
  // Inside: the small box's volume; apart or flat: nothing.
  EXPECT_NEAR(intersection_volume(cube, make_box({0.2, 0.1, 0}, {0.3, 0.2, 0.1}, turned.rotation)), 0.048,
              1e-12);
  EXPECT_EQ(intersection_volume(cube, make_box({3, 0, 0}, {1, 1, 1})), 0.0);
  EXPECT_EQ(intersection_volume(cube, make_box({0, 0, 0}, {1, 1, 0})), 0.0);
  EXPECT_EQ(volume_iou(make_box({0, 0, 0}, {0, 0, 0}), make_box({0, 0, 0}, {0, 0, 0})), 0.0);
}

// Random pairs against counting a fine grid of points of box a that lie inside box b.
TEST(BoxVolumeTest, AgreesWithPointCountingOnRandomPairs) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto random_box = [&] {
    const Eigen::Quaterniond q(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5,
                               unit(random) - 0.5);
    return make_box({unit(random) * 0.4, unit(random) * 0.4, unit(random) * 0.4},
                    {0.1 + unit(random) * 0.3, 0.1 + unit(random) * 0.3, 0.1 + unit(random) * 0.3},
                    q.normalized());
  };
  for (int pair = 0; pair < 20; ++pair) {
    const Box a = random_box(), b = random_box();
    const int n = 60;
    int inside = 0;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        for (int k = 0; k < n; ++k) {
          const Eigen::Vector3d p_A = (Eigen::Vector3d(i, j, k).array() + 0.5) / n * 2.0 - 1.0;
          inside += b.contains(a.center + a.rotation * p_A.cwiseProduct(a.half_extents));
        }
      }
    }
    const double counted = a.volume() * inside / (n * n * n);
    EXPECT_NEAR(intersection_volume(a, b), counted, 0.01 * a.volume()) << pair;
    EXPECT_NEAR(intersection_volume(a, b), intersection_volume(b, a), 1e-12) << pair;
  }
}

}  // namespace
}  // namespace cellmap
