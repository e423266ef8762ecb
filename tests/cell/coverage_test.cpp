// SPDX-License-Identifier: Apache-2.0
#include "coverage.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

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

// The centres of the 2 cm voxels filling [lo, hi) (metres, multiples of 2 cm).
std::vector<Eigen::Vector3d> voxels(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  std::vector<Eigen::Vector3d> out;
  const Eigen::Vector3i n = ((hi - lo) / 0.02).array().round().cast<int>();
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) out.push_back(lo + 0.02 * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
    }
  }
  return out;
}

// A 2 m × 1 m × 0.28 m box with two groups of voxels outside it: a row on its top face (a surface filling
// in, within reach) grows it; a 0.3 m × 0.08 m × 0.2 m object against its side reaches 8 cm beyond it, and
// gets a box of its own, although taking it voxel by voxel would grow the box by less than a tenth.
TEST(CoverTest, AGroupWithinReachGrowsTheBoxAnObjectBeyondItGetsABoxOfItsOwn) {
  Reconciled reconciled;
  reconciled.boxes = {box_at({1.0, 0.5, 0.14}, {1.0, 0.5, 0.14}, 0.0)};
  reconciled.boxes[0].id = 1;
  reconciled.next_id = 2;
  std::vector<Eigen::Vector3d> outside = voxels({0.5, 0.5, 0.28}, {0.7, 0.52, 0.30});
  const std::vector<Eigen::Vector3d> object = voxels({0.86, 1.0, 0.0}, {1.16, 1.08, 0.2});
  outside.insert(outside.end(), object.begin(), object.end());
  CoverParams options;
  options.reach = 0.04;
  cover(reconciled, outside, options);

  ASSERT_EQ(reconciled.boxes.size(), 2u);
  ASSERT_EQ(reconciled.modified.size(), 1u);
  EXPECT_EQ(reconciled.modified[0].id, 1u);
  const Region grown = bounds_of(reconciled.boxes[0]);
  EXPECT_NEAR(grown.max.z(), 0.30, 1e-6);
  EXPECT_NEAR(grown.max.y(), 1.0, 1e-6) << "the box grew into the object";
  ASSERT_EQ(reconciled.added.size(), 1u);
  EXPECT_EQ(reconciled.added[0].id, 2u);
  EXPECT_EQ(reconciled.next_id, 3u);
  for (const Eigen::Vector3d& c : object) EXPECT_TRUE(holds_cube(reconciled.added[0], c, 0.02));
  for (const Eigen::Vector3d& c : outside) {
    const auto holds = [&](const Box& b) { return holds_cube(b, c, 0.02); };
    EXPECT_TRUE(std::any_of(reconciled.boxes.begin(), reconciled.boxes.end(), holds));
  }
}

}  // namespace
}  // namespace cellmap
