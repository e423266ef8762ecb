#include "coverage.hpp"

#include <gtest/gtest.h>

#include <random>

namespace cellmap {
namespace {

Box box_at(const Eigen::Vector3d& center, const Eigen::Vector3d& half_extents, double yaw) {
  Box box;
  box.center = center;
  box.half_extents = half_extents;
  box.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return box;
}

TEST(CubeHoldersTest, HoldWhereSomeBoxHoldsTheWholeCube) {
  const double edge = 0.05;
  const std::vector<Box> boxes{box_at({0, 0, 0}, {0.1, 0.1, 0.1}, 0.0),
                               box_at({1, 0, 0}, {0.2, 0.1, 0.1}, M_PI / 4)};
  CubeHolders holders(boxes, edge);
  EXPECT_TRUE(holders.hold({0.075, 0, 0}));  // the cube touches the first box's face from inside
  EXPECT_FALSE(holders.hold({0.08, 0, 0}));  // it pokes out by 5 mm
  EXPECT_TRUE(holders.hold({1, 0, 0}));      // the second box, after the first held the last one
  EXPECT_TRUE(holders.hold({0, 0, 0}));      // back to the first
  EXPECT_FALSE(holders.hold({0.5, 0, 0}));   // between them
  EXPECT_FALSE(CubeHolders({}, edge).hold({0, 0, 0}));
}

// The same answer as asking holds_cube of every box, whichever box held the voxel before.
TEST(CubeHoldersTest, AgreesWithHoldsCubeOnEveryVoxel) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> place(-1.0, 1.0), size(0.02, 0.4), angle(-M_PI, M_PI);
  std::vector<Box> boxes;
  for (int i = 0; i < 25; ++i) {
    Box box = box_at({place(random), place(random), place(random)},
                     {size(random), size(random), size(random)}, angle(random));
    box.rotation =
        Eigen::Quaterniond(Eigen::AngleAxisd(angle(random), Eigen::Vector3d::UnitX())) * box.rotation;
    boxes.push_back(box);
  }
  const double edge = 0.05;
  CubeHolders holders(boxes, edge);
  int held = 0;
  for (double z = -1.2; z <= 1.2; z += edge) {
    for (double y = -1.2; y <= 1.2; y += edge) {
      for (double x = -1.2; x <= 1.2; x += edge) {
        const Eigen::Vector3d c(x, y, z);
        bool expected = false;
        for (const Box& box : boxes) expected = expected || holds_cube(box, c, edge);
        ASSERT_EQ(holders.hold(c), expected) << x << " " << y << " " << z;
        held += expected;
      }
    }
  }
  EXPECT_GT(held, 1000);  // the boxes hold many voxels: the test asks both answers often
}

}  // namespace
}  // namespace cellmap
