// SPDX-License-Identifier: Apache-2.0
#include "cellmap/boxes/box.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

Box rotated_box() {
  Box box;
  box.id = 7;
  box.center = {0.5, 0.2, 0.1};
  box.half_extents = {0.2, 0.1, 0.05};
  box.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()));
  box.points = 1234;
  return box;
}

TEST(BoxTest, ContainsUsesTheBoxFrame) {
  const Box box = rotated_box();
  // Along the box's own x axis (45 degrees in the cell) 0.19 is inside, 0.21 outside.
  const Eigen::Vector3d axis_x = box.rotation * Eigen::Vector3d::UnitX();
  EXPECT_TRUE(box.contains(box.center + 0.19 * axis_x));
  EXPECT_FALSE(box.contains(box.center + 0.21 * axis_x));
  EXPECT_TRUE(box.contains(box.center + 0.21 * axis_x, 0.011));
  // The cell-frame x direction at 0.19 leaves the rotated box's y half-extent of 0.1.
  EXPECT_FALSE(box.contains(box.center + Eigen::Vector3d(0.19, 0, 0)));
  EXPECT_DOUBLE_EQ(box.volume(), 8 * 0.2 * 0.1 * 0.05);
  EXPECT_FALSE(box.is_axis_aligned());
  EXPECT_TRUE(Box{}.is_axis_aligned());
}

TEST(BoxTest, JsonRoundTripKeepsEveryField) {
  BoxSet set;
  set.version = 3;
  set.boxes = {rotated_box(), Box{}};
  const BoxSet back = box_set_from_json(to_json(set));
  EXPECT_EQ(back.version, 3u);
  EXPECT_EQ(back.frame, "cell");
  ASSERT_EQ(back.boxes.size(), 2u);
  EXPECT_EQ(back.boxes[0].id, 7u);
  EXPECT_EQ(back.boxes[0].points, 1234u);
  EXPECT_TRUE(back.boxes[0].center.isApprox(set.boxes[0].center, 1e-15));
  EXPECT_TRUE(back.boxes[0].half_extents.isApprox(set.boxes[0].half_extents, 1e-15));
  // Bit-identical, so a box persisted and read back is not a "modified" box.
  EXPECT_EQ(back.boxes[0].rotation.coeffs(), set.boxes[0].rotation.coeffs());
  EXPECT_EQ(back.boxes[0].center, set.boxes[0].center);
}

TEST(BoxTest, JsonMatchesTheContract) {
  const std::string text = R"({ "version": 3, "frame": "cell",
  "boxes": [ { "id": 7, "center": [0.5, 0.2, 0.1], "half_extents": [0.2, 0.1, 0.1],
               "rotation": [1, 0, 0, 0], "points": 1234 } ] })";
  const BoxSet set = box_set_from_json(text);
  ASSERT_EQ(set.boxes.size(), 1u);
  EXPECT_EQ(set.boxes[0].id, 7u);
  EXPECT_TRUE(set.boxes[0].is_axis_aligned());
  EXPECT_DOUBLE_EQ(set.boxes[0].half_extents.z(), 0.1);
}

TEST(BoxTest, SpaceIsWrittenForUnknownBoxesOnlyAndReadBack) {
  Box unknown = rotated_box();
  unknown.space = BoxSpace::kUnknown;
  const std::string text = to_json(BoxSet{1, "cell", {unknown, Box{}}});
  EXPECT_NE(text.find("\"space\": \"unknown\""), std::string::npos);
  EXPECT_EQ(text.find("\"occupied\""), std::string::npos);  // absent means occupied
  const BoxSet back = box_set_from_json(text);
  ASSERT_EQ(back.boxes.size(), 2u);
  EXPECT_EQ(back.boxes[0].space, BoxSpace::kUnknown);
  EXPECT_EQ(back.boxes[1].space, BoxSpace::kOccupied);
  // Older files have no space at all: every box in them holds occupied space.
  const BoxSet old = box_set_from_json(R"({"version": 1, "frame": "cell", "boxes": [{"id": 1,
      "center": [0, 0, 0], "half_extents": [1, 1, 1], "rotation": [1, 0, 0, 0], "points": 0}]})");
  EXPECT_EQ(old.boxes[0].space, BoxSpace::kOccupied);
  EXPECT_STREQ(space_name(BoxSpace::kUnknown), "unknown");
}

std::string error_of(const std::string& text) {
  try {
    (void)box_set_from_json(text, "in.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(BoxTest, MalformedJsonNamesTheField) {
  EXPECT_NE(error_of("{").find("in.json: not valid JSON"), std::string::npos);
  EXPECT_EQ(error_of(R"({"version": 1, "frame": "cell"})"), "in.json: document.boxes: is missing");
  EXPECT_EQ(error_of(R"({"version": -1, "frame": "cell", "boxes": []})"),
            "in.json: version: must be a non-negative integer");
  EXPECT_EQ(error_of(R"({"version": 1, "frame": "cell", "boxes": [{"id": 1, "center": [0, 0],
      "half_extents": [1, 1, 1], "rotation": [1, 0, 0, 0], "points": 0}]})"),
            "in.json: boxes[0].center: must be an array of 3 numbers");
  EXPECT_EQ(error_of(R"({"version": 1, "frame": "cell", "boxes": [{"id": 1, "center": [0, 0, 0],
      "half_extents": [1, -1, 1], "rotation": [1, 0, 0, 0], "points": 0}]})"),
            "in.json: boxes[0].half_extents: must not be negative");
  EXPECT_EQ(error_of(R"({"version": 1, "frame": "cell", "boxes": [{"id": 1, "center": [0, 0, 0],
      "half_extents": [1, 1, 1], "rotation": [2, 0, 0, 0], "points": 0}]})"),
            "in.json: boxes[0].rotation: must be a unit quaternion [w, x, y, z]");
  EXPECT_EQ(error_of(R"({"version": 1, "frame": "cell", "boxes": [{"id": 1, "center": [0, 0, 0],
      "half_extents": [1, 1, 1], "rotation": [1, 0, 0, 0], "points": 0, "space": "hazard"}]})"),
            "in.json: boxes[0].space: must be \"occupied\" or \"unknown\"");
}

}  // namespace
}  // namespace cellmap
