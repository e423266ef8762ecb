// SPDX-License-Identifier: Apache-2.0
#include "cellmap/unknown/unknown_boxes.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"
#include "occupancy/box_scene.hpp"

namespace cellmap {
namespace {

using testing::AlignedBox;

// A camera at the origin looking along +z (cell frame = sensor frame) at a near wall (z 2.0–2.1, x from
// `near_x_min` to 1) in front of a far wall (z 4.0–4.1): the space behind the near wall is never crossed.
Sweep view(double near_x_min) {
  std::vector<AlignedBox> scene = {{{-2, -2, 4.0}, {2, 2, 4.1}}};
  if (near_x_min < 1.0) scene.push_back({{near_x_min, -1, 2.0}, {1, 1, 2.1}});
  Sweep sweep;
  sweep.scans.push_back(
      testing::render_scan(scene, Eigen::Isometry3d::Identity(), testing::kinect_intrinsics(320, 240)));
  return sweep;
}

UnknownSpaceConfig behind_the_wall() {
  UnknownSpaceConfig config;
  config.workspace = Region{{-0.5, -0.5, 1.0}, {0.5, 0.5, 3.0}};
  return config;
}

bool any_holds(const std::vector<Box>& boxes, const Eigen::Vector3d& p_C) {
  for (const Box& box : boxes) {
    if (box.contains(p_C)) return true;
  }
  return false;
}

TEST(UnknownBoxesTest, CoversTheSpaceBehindAWallAndNotTheSpaceBeforeIt) {
  OccupancyMap map;
  map.integrate(view(-1.0));
  UnknownBoxes unknown(behind_the_wall());
  std::uint64_t next_id = 7;
  const UnknownChange change = unknown.cover_all(map, {}, next_id);
  ASSERT_EQ(change.added.size(), 1U);  // one block behind the wall, up to the workspace's far side
  EXPECT_TRUE(change.removed.empty());
  const Box& box = unknown.boxes().front();
  EXPECT_EQ(box.id, 7U);
  EXPECT_EQ(next_id, 8U);
  EXPECT_EQ(box.space, BoxSpace::kUnknown);
  EXPECT_TRUE(box.contains({0.0, 0.0, 2.5}));
  EXPECT_TRUE(box.contains({0.45, 0.45, 2.95}));
  EXPECT_FALSE(box.contains({0.0, 0.0, 1.9}));  // seen free in front of the wall
  EXPECT_NEAR(box.center.z(), 2.55, 0.03);      // from the wall's hit layer (2.02 m) to 3 m
  EXPECT_GT(unknown.last_cover().unknown_volume, 0.9);
}

TEST(UnknownBoxesTest, ShrinksWithinItsOwnExtentAsTheSpaceBehindComesIntoView) {
  OccupancyMap map;
  map.integrate(view(-1.0));
  UnknownBoxes unknown(behind_the_wall());
  std::uint64_t next_id = 1;
  (void)unknown.cover_all(map, {}, next_id);
  const Box before = unknown.boxes().front();

  map.integrate(view(0.0));  // the wall's left half is gone: the space behind it is seen
  const UnknownChange change = unknown.shrink(map, {}, next_id);
  ASSERT_EQ(change.modified.size(), 1U);
  EXPECT_TRUE(change.added.empty());
  const Box& after = unknown.boxes().front();
  EXPECT_EQ(after.id, before.id);
  EXPECT_TRUE(after.contains({0.25, 0.0, 2.5}));
  EXPECT_FALSE(after.contains({-0.25, 0.0, 2.5}));
  // Never grows: every corner of the new box lies in the old one.
  EXPECT_TRUE(
      ((after.center - after.half_extents).array() >= (before.center - before.half_extents).array() - 1e-9)
          .all());
  EXPECT_TRUE(
      ((after.center + after.half_extents).array() <= (before.center + before.half_extents).array() + 1e-9)
          .all());

  map.integrate(view(1.0));  // the whole wall is gone
  const UnknownChange gone = unknown.shrink(map, {}, next_id);
  EXPECT_EQ(gone.removed, std::vector<std::uint64_t>{before.id});
  EXPECT_TRUE(unknown.boxes().empty());
}

TEST(UnknownBoxesTest, ASweepOfTheSameViewChangesNothing) {
  OccupancyMap map;
  map.integrate(view(-1.0));
  UnknownBoxes unknown(behind_the_wall());
  std::uint64_t next_id = 1;
  (void)unknown.cover_all(map, {}, next_id);
  map.integrate(view(-1.0));
  EXPECT_TRUE(unknown.shrink(map, {}, next_id).empty());
  EXPECT_EQ(next_id, 2U);
}

TEST(UnknownBoxesTest, TheRobotsBodyNeedsNoCover) {
  OccupancyMap map;
  map.integrate(view(-1.0));
  UnknownSpaceConfig config = behind_the_wall();
  config.workspace = Region{{-0.5, -0.5, 2.2}, {0.5, 0.5, 3.0}};  // all behind the wall
  UnknownBoxes unknown(config);
  Box body;  // the robot stands in all of it
  body.center = {0.0, 0.0, 2.6};
  body.half_extents = {0.6, 0.6, 0.5};
  std::uint64_t next_id = 1;
  EXPECT_TRUE(unknown.cover_all(map, {body}, next_id).added.empty());
  body.half_extents.x() = 0.1;  // a slimmer robot leaves room to hide in on both sides
  EXPECT_FALSE(unknown.cover_all(map, {body}, next_id).added.empty());
  EXPECT_TRUE(any_holds(unknown.boxes(), {-0.3, 0.0, 2.6}));
  EXPECT_TRUE(any_holds(unknown.boxes(), {0.3, 0.0, 2.6}));
}

TEST(UnknownBoxesTest, RestoredBoxesAreUnknownAndSorted) {
  Box a, b;
  a.id = 9;
  b.id = 3;
  const UnknownBoxes unknown(behind_the_wall(), {a, b});
  ASSERT_EQ(unknown.boxes().size(), 2U);
  EXPECT_EQ(unknown.boxes()[0].id, 3U);
  EXPECT_EQ(unknown.boxes()[1].space, BoxSpace::kUnknown);
}

std::string error_of(const std::string& yaml) {
  try {
    (void)UnknownSpaceConfig::from_yaml(YamlMap::parse(yaml, "c.yaml").child("unknown"));
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(UnknownBoxesTest, ConfigReadsEveryKeyAndNamesBadOnes) {
  const UnknownSpaceConfig c = UnknownSpaceConfig::from_yaml(
      YamlMap::parse(
          "unknown: {enabled: true, workspace: {lower: [0, 0, 0], upper: [1, 2, 3]}, min_size: 0.2, "
          "max_free_share: 0.1, max_boxes: 5, check_sweeps: 3}",
          "c.yaml")
          .child("unknown"));
  ASSERT_TRUE(c.workspace.has_value());
  EXPECT_EQ(c.workspace->max, Eigen::Vector3d(1, 2, 3));
  EXPECT_DOUBLE_EQ(c.cover.min_size, 0.2);
  EXPECT_EQ(c.cover.max_boxes, 5);
  EXPECT_EQ(c.check_sweeps, 3);
  EXPECT_TRUE(c.active());
  EXPECT_FALSE(UnknownSpaceConfig{}.active());  // no workspace: not tracked
  EXPECT_NE(error_of("unknown: {colour: grey}").find("unknown.colour: unknown key"), std::string::npos);
  EXPECT_NE(error_of("unknown: {check_sweeps: 0}").find("unknown.check_sweeps"), std::string::npos);
  EXPECT_NE(
      error_of("unknown: {workspace: {lower: [0, 0, 0], upper: [1, 0, 1]}}").find("unknown.workspace.upper"),
      std::string::npos);
  EXPECT_THROW(UnknownBoxes(UnknownSpaceConfig{}), Error);
}

}  // namespace
}  // namespace cellmap
