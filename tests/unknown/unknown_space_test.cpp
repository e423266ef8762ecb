// SPDX-License-Identifier: Apache-2.0
#include "cellmap/unknown/unknown_space.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cellmap/common/error.hpp"
#include "occupancy/box_scene.hpp"

namespace cellmap {
namespace {

constexpr double kVoxel = 0.05;
constexpr double kVoxelVolume = kVoxel * kVoxel * kVoxel;

VoxelStateGrid free_grid(const Eigen::Vector3i& size) {
  VoxelStateGrid grid(size, kVoxel, Eigen::Vector3d::Zero());
  grid.fill(Eigen::Vector3i::Zero(), size, VoxelState::free);
  return grid;
}

// Voxel indices [low, high) as a region of the cell frame.
Region region_of(const Eigen::Vector3i& low, const Eigen::Vector3i& high) {
  return {low.cast<double>() * kVoxel, high.cast<double>() * kVoxel};
}

Box box_over(const Region& region) {
  Box box;
  box.center = 0.5 * (region.min + region.max);
  box.half_extents = 0.5 * (region.max - region.min);
  return box;
}

void expect_box_spans(const Box& box, const Region& expected) {
  EXPECT_TRUE(box.center.isApprox(0.5 * (expected.min + expected.max), 1e-9)) << box.center.transpose();
  EXPECT_TRUE(box.half_extents.isApprox(0.5 * (expected.max - expected.min), 1e-9))
      << box.half_extents.transpose();
  EXPECT_TRUE(box.is_axis_aligned());
}

// Whether the centre of voxel (x, y, z) of a grid at the origin lies in some box.
bool voxel_in_some_box(const std::vector<Box>& boxes, int x, int y, int z) {
  const Eigen::Vector3d centre = (Eigen::Vector3d(x, y, z) + Eigen::Vector3d::Constant(0.5)) * kVoxel;
  for (const Box& box : boxes) {
    if (box.contains(centre)) return true;
  }
  return false;
}

TEST(UnknownSpaceTest, ANeverObservedWorkspaceIsOneBox) {
  const VoxelStateGrid grid({20, 10, 8}, kVoxel, Eigen::Vector3d::Zero());
  const UnknownCover cover = cover_unknown(grid);
  ASSERT_EQ(cover.boxes.size(), 1U);
  expect_box_spans(cover.boxes[0], region_of({0, 0, 0}, {20, 10, 8}));
  EXPECT_EQ(cover.boxes[0].points, 1600U);
  EXPECT_NEAR(cover.unknown_volume, 1600 * kVoxelVolume, 1e-12);
  EXPECT_NEAR(cover.grid_volume, 1600 * kVoxelVolume, 1e-12);
  EXPECT_EQ(cover.ignored_volume, 0.0);
  EXPECT_EQ(cover.blocked_free_volume, 0.0);
}

TEST(UnknownSpaceTest, AnObservedWorkspaceHasNoBox) {
  const UnknownCover cover = cover_unknown(free_grid({10, 10, 10}));
  EXPECT_TRUE(cover.boxes.empty());
  EXPECT_EQ(cover.unknown_volume, 0.0);
  EXPECT_EQ(cover.boxed_volume, 0.0);
}

TEST(UnknownSpaceTest, APocketIsBoxedExactlyAndOneTooSmallForALimbIsIgnored) {
  VoxelStateGrid grid = free_grid({20, 20, 20});
  grid.fill({3, 4, 5}, {7, 9, 8}, VoxelState::unknown);  // 4 × 5 × 3 voxels: 20 × 25 × 15 cm
  grid.set(15, 15, 15, VoxelState::unknown);             // one voxel: 5 cm
  const UnknownCover cover = cover_unknown(grid);        // min_size 10 cm = 2 voxels
  ASSERT_EQ(cover.boxes.size(), 1U);
  expect_box_spans(cover.boxes[0], region_of({3, 4, 5}, {7, 9, 8}));
  EXPECT_NEAR(cover.unknown_volume, 61 * kVoxelVolume, 1e-12);
  EXPECT_NEAR(cover.ignored_volume, kVoxelVolume, 1e-12);
  EXPECT_EQ(cover.blocked_free_volume, 0.0);
}

TEST(UnknownSpaceTest, ThinShellsAndRayGapsAreIgnoredButAZeroSizeKeepsThem) {
  VoxelStateGrid grid = free_grid({20, 20, 20});
  grid.fill({0, 0, 10}, {20, 20, 11}, VoxelState::unknown);                // a sheet one voxel thick
  for (int x = 0; x < 20; x += 2) grid.set(x, 3, 3, VoxelState::unknown);  // gaps between rays
  EXPECT_TRUE(cover_unknown(grid).boxes.empty());
  EXPECT_NEAR(cover_unknown(grid).ignored_volume, 410 * kVoxelVolume, 1e-12);

  UnknownConfig every_voxel;
  every_voxel.min_size = 0.0;
  const UnknownCover cover = cover_unknown(grid, every_voxel);
  EXPECT_EQ(cover.ignored_volume, 0.0);
  for (int x = 0; x < 20; x += 2) EXPECT_TRUE(voxel_in_some_box(cover.boxes, x, 3, 3)) << x;
  EXPECT_TRUE(voxel_in_some_box(cover.boxes, 7, 13, 10));
}

TEST(UnknownSpaceTest, AnLShapeIsTwoTightBoxesOrOneThatBlocksItsCorner) {
  VoxelStateGrid grid = free_grid({20, 20, 4});
  grid.fill({0, 0, 0}, {10, 2, 4}, VoxelState::unknown);  // the L's foot
  grid.fill({0, 0, 0}, {2, 10, 4}, VoxelState::unknown);  // its leg
  UnknownConfig tight;
  tight.max_free_share = 0.0;
  const UnknownCover two = cover_unknown(grid, tight);
  EXPECT_EQ(two.boxes.size(), 2U);
  EXPECT_EQ(two.blocked_free_volume, 0.0);
  EXPECT_NEAR(two.boxed_volume, (20 + 20 - 4) * 4 * kVoxelVolume, 1e-12);

  tight.max_boxes = 1;
  const UnknownCover one = cover_unknown(grid, tight);
  ASSERT_EQ(one.boxes.size(), 1U);
  expect_box_spans(one.boxes[0], region_of({0, 0, 0}, {10, 10, 4}));
  EXPECT_NEAR(one.blocked_free_volume, 8 * 8 * 4 * kVoxelVolume, 1e-12);
}

TEST(UnknownSpaceTest, OccupiedVoxelsCostNothingToCover) {
  // An obstacle's unseen inside and the shadow behind it: one box through the obstacle blocks no free space.
  VoxelStateGrid grid = free_grid({20, 20, 10});
  grid.fill({5, 5, 0}, {9, 9, 6}, VoxelState::occupied);
  grid.fill({6, 6, 0}, {8, 8, 5}, VoxelState::unknown);   // inside
  grid.fill({9, 5, 0}, {15, 9, 6}, VoxelState::unknown);  // shadow
  const UnknownCover cover = cover_unknown(grid);
  ASSERT_EQ(cover.boxes.size(), 1U);
  expect_box_spans(cover.boxes[0], region_of({6, 5, 0}, {15, 9, 6}));  // the shell at x = 5 holds no unknown
  EXPECT_EQ(cover.blocked_free_volume, 0.0);
}

TEST(UnknownSpaceTest, EveryPocketVoxelIsCoveredInRandomScenes) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> corner(0, 27), extent(2, 8);
    VoxelStateGrid grid = free_grid({30, 30, 20});
    for (int blob = 0; blob < 25; ++blob) {
      const Eigen::Vector3i low(corner(rng), corner(rng), corner(rng) % 17);
      grid.fill(low, low + Eigen::Vector3i(extent(rng), extent(rng), extent(rng)), VoxelState::unknown);
    }
    UnknownConfig every_voxel;
    every_voxel.min_size = 0.0;
    const UnknownCover cover = cover_unknown(grid, every_voxel);
    EXPECT_LE(cover.boxes.size(), 20U) << "seed " << seed;
    for (int z = 0; z < 20; ++z) {
      for (int y = 0; y < 30; ++y) {
        for (int x = 0; x < 30; ++x) {
          if (grid.at(x, y, z) != VoxelState::unknown) continue;
          ASSERT_TRUE(voxel_in_some_box(cover.boxes, x, y, z)) << "seed " << seed << " voxel " << x << y << z;
        }
      }
    }
    EXPECT_NEAR(cover.boxed_volume - cover.blocked_free_volume, cover.unknown_volume, 1e-9)
        << "seed " << seed;
  }
}

TEST(UnknownSpaceTest, TheGridOfAFusedMapHoldsTheMapsStatesAndTheShadowIsBoxed) {
  // A camera 2 m above the floor looks down at a crate; behind and under the crate it sees nothing.
  OccupancyConfig config;
  config.resolution = kVoxel;
  OccupancyMap map(config);
  const std::vector<testing::AlignedBox> scene = {{{-3, -3, -0.1}, {3, 3, 0.0}},         // floor
                                                  {{0.4, -0.2, 0.0}, {0.7, 0.2, 0.8}}};  // crate
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  X_CS.translate(Eigen::Vector3d(-0.5, 0.0, 2.0));
  X_CS.rotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));  // looking down (sensor z to −z)
  X_CS.rotate(Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitY()));  // tilted towards +x
  Sweep sweep;
  sweep.scans.push_back(testing::render_scan(scene, X_CS, testing::kinect_intrinsics(320, 240)));
  map.integrate(sweep);

  const Region workspace{{-0.5, -0.5, 0.02}, {1.5, 0.5, 1.0}};
  const VoxelStateGrid grid = VoxelStateGrid::of(map, workspace);
  int unknown = 0;
  for (int z = 0; z < grid.size().z(); ++z) {
    for (int y = 0; y < grid.size().y(); ++y) {
      for (int x = 0; x < grid.size().x(); ++x) {
        const Eigen::Vector3d centre =
            grid.origin() + (Eigen::Vector3d(x, y, z) + Eigen::Vector3d::Constant(0.5)) * kVoxel;
        ASSERT_EQ(grid.at(x, y, z), map.state(centre)) << centre.transpose();
        unknown += grid.at(x, y, z) == VoxelState::unknown;
      }
    }
  }
  ASSERT_GT(unknown, 0);

  const UnknownCover cover = cover_unknown(grid);
  EXPECT_GE(cover.boxes.size(), 1U);
  EXPECT_LE(cover.boxes.size(), 20U);
  const Eigen::Vector3d behind_the_crate(0.9, 0.0, 0.1);  // in its shadow: the camera is on the −x side
  ASSERT_EQ(map.state(behind_the_crate), VoxelState::unknown);
  bool boxed = false;
  for (const Box& box : cover.boxes) boxed = boxed || box.contains(behind_the_crate);
  EXPECT_TRUE(boxed);
  EXPECT_LE(cover.blocked_free_volume, 0.25 * cover.boxed_volume);
}

TEST(UnknownSpaceTest, BadConfigsAndGridsAreRefusedByName) {
  UnknownConfig config;
  config.max_free_share = 0.7;
  EXPECT_THROW(config.validate(), Error);
  config = {};
  config.min_size = std::nan("");
  EXPECT_THROW(config.validate(), Error);
  config = {};
  config.max_boxes = 0;
  try {
    config.validate();
    FAIL() << "max_boxes 0 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown.max_boxes"), std::string::npos) << e.what();
  }
  EXPECT_THROW(VoxelStateGrid({0, 1, 1}, kVoxel, Eigen::Vector3d::Zero()), Error);
  EXPECT_THROW(VoxelStateGrid({1024, 1024, 1024}, kVoxel, Eigen::Vector3d::Zero()), Error);
  const OccupancyMap map;
  EXPECT_THROW((void)VoxelStateGrid::of(map, Region{{0, 0, 0}, {0, 0, 0}}), Error);
}

TEST(UnknownSpaceTest, FreesACubeOnlyWhereNoBoxHoldsOneWholeCube) {
  const VoxelStateGrid grid({30, 20, 20}, kVoxel, Eigen::Vector3d::Zero());
  // Two boxes over the grid's x ends leave a slab of `gap` voxels between them.
  const auto ends_apart = [&](int gap) {
    const int left = (30 - gap) / 2;
    return std::vector<Box>{box_over(region_of({0, 0, 0}, {left, 20, 20})),
                            box_over(region_of({left + gap, 0, 0}, {30, 20, 20}))};
  };
  const double edge = 10 * kVoxel;
  EXPECT_TRUE(frees_a_cube(grid, ends_apart(10), edge));
  EXPECT_FALSE(frees_a_cube(grid, ends_apart(9), edge));  // a 9-voxel slab holds no 10-voxel cube
  EXPECT_FALSE(frees_a_cube(grid, {box_over(region_of({0, 0, 0}, {30, 20, 20}))}, edge));
  EXPECT_TRUE(frees_a_cube(grid, {}, edge));
}

}  // namespace
}  // namespace cellmap
