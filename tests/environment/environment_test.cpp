// SPDX-License-Identifier: Apache-2.0
#include "cellmap/environment/environment.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

Box box(std::uint64_t id, double x, double half = 0.1) {
  Box b;
  b.id = id;
  b.center = {x, 0.5, 0.25};
  b.half_extents = {half, half, half};
  b.points = 100 + id;
  return b;
}

TEST(EnvironmentTest, StoresBoxesSortedAndRefusesDuplicateIds) {
  const Environment env("cell-a", 3, 42, {box(9, 1.0), box(2, 2.0), box(5, 3.0)});
  ASSERT_EQ(env.boxes().size(), 3u);
  EXPECT_EQ(env.boxes()[0].id, 2u);
  EXPECT_EQ(env.boxes()[2].id, 9u);
  ASSERT_NE(env.find(5), nullptr);
  EXPECT_EQ(env.find(5)->center.x(), 3.0);
  EXPECT_EQ(env.find(4), nullptr);
  EXPECT_THROW(Environment("cell-a", 1, 0, {box(1, 0.0), box(1, 1.0)}), Error);
  EXPECT_THROW(Environment("", 1, 0, {}), Error);
}

TEST(EnvironmentTest, DiffFindsAddedModifiedAndRemoved) {
  const Environment before("cell-a", 4, 10, {box(1, 0.0), box(2, 1.0), box(3, 2.0), box(4, 3.0)});
  Box moved = box(2, 1.5);
  Box regrown = box(4, 3.0, 0.2);
  const Environment after("cell-a", 5, 20, {box(1, 0.0), moved, regrown, box(7, 9.0)});
  const EnvironmentDelta delta = diff(before, after);
  EXPECT_EQ(delta.cell, "cell-a");
  EXPECT_EQ(delta.from_version, 4u);
  EXPECT_EQ(delta.to_version, 5u);
  EXPECT_EQ(delta.stamp_ns, 20);
  ASSERT_EQ(delta.added.size(), 1u);
  EXPECT_EQ(delta.added[0].id, 7u);
  ASSERT_EQ(delta.modified.size(), 2u);
  EXPECT_EQ(delta.modified[0].id, 2u);
  EXPECT_EQ(delta.modified[0].center.x(), 1.5);
  EXPECT_EQ(delta.modified[1].id, 4u);
  EXPECT_EQ(delta.removed, std::vector<std::uint64_t>{3});
  EXPECT_FALSE(delta.empty());
  EXPECT_EQ(apply(before, delta), after);
}

TEST(EnvironmentTest, DiffOfEqualBoxesIsEmptyAndAnyFieldCounts) {
  const Environment a("c", 1, 0, {box(1, 0.0)});
  EXPECT_TRUE(diff(a, Environment("c", 2, 0, {box(1, 0.0)})).empty());
  Box fewer_points = box(1, 0.0);
  fewer_points.points = 3;
  EXPECT_EQ(diff(a, Environment("c", 2, 0, {fewer_points})).modified.size(), 1u);
  Box turned = box(1, 0.0);
  turned.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()));
  EXPECT_EQ(diff(a, Environment("c", 2, 0, {turned})).modified.size(), 1u);
}

TEST(EnvironmentTest, DiffRefusesOtherCellOrOlderVersion) {
  const Environment a("c", 3, 0, {});
  EXPECT_THROW((void)diff(a, Environment("d", 4, 0, {})), Error);
  EXPECT_THROW((void)diff(a, Environment("c", 3, 0, {})), Error);
  EXPECT_THROW((void)diff(a, Environment("c", 2, 0, {})), Error);
}

TEST(EnvironmentTest, ApplyRefusesMismatchedDeltas) {
  const Environment env("c", 3, 0, {box(1, 0.0)});
  EnvironmentDelta delta;
  delta.cell = "c";
  delta.from_version = 3;
  delta.to_version = 4;
  EXPECT_EQ(apply(env, delta).version(), 4u);

  EnvironmentDelta wrong = delta;
  wrong.from_version = 2;
  EXPECT_THROW((void)apply(env, wrong), Error);
  wrong = delta;
  wrong.cell = "d";
  EXPECT_THROW((void)apply(env, wrong), Error);
  wrong = delta;
  wrong.to_version = 3;
  EXPECT_THROW((void)apply(env, wrong), Error);
  wrong = delta;
  wrong.added = {box(1, 5.0)};
  EXPECT_THROW((void)apply(env, wrong), Error);
  wrong = delta;
  wrong.modified = {box(2, 5.0)};
  EXPECT_THROW((void)apply(env, wrong), Error);
  wrong = delta;
  wrong.removed = {2};
  try {
    (void)apply(env, wrong);
    FAIL() << "removing an absent id must throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("removed: box id 2"), std::string::npos) << e.what();
  }
}

// Found by fuzz_dds_samples: a delta from the network whose cell name holds a line break made a refusal of
// two lines (a forged log line). The cell is quoted with '?' for each control character.
TEST(EnvironmentTest, RefusalQuotesACellNameWithALineBreakOnOneLine) {
  const Environment env("c\nforged", 3, 0, {});
  EnvironmentDelta delta;
  delta.cell = env.cell();
  delta.from_version = 3;
  delta.to_version = 4;
  delta.modified = {box(2, 5.0)};
  for (const std::string& cell : {env.cell(), std::string("d\rforged")}) {
    delta.cell = cell;
    try {
      (void)apply(env, delta);
      FAIL() << "a delta of an absent box or another cell must throw";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find_first_of("\n\r"), std::string::npos) << what;
      EXPECT_NE(what.find("forged"), std::string::npos) << what;
    }
  }
}

TEST(EnvironmentTest, ChainOfDeltasReproducesEveryVersion) {
  // Versions built by random edits: applying the diffs in order must rebuild each version exactly.
  std::srand(7);
  Environment current("c");
  Environment rebuilt("c");
  std::uint64_t next_id = 1;
  for (std::uint64_t version = 1; version <= 200; ++version) {
    std::vector<Box> boxes = current.boxes();
    const int action = std::rand() % 3;
    if (action == 0 || boxes.empty()) {
      boxes.push_back(box(next_id++, std::rand() % 100 / 10.0));
    } else if (action == 1) {
      boxes.erase(boxes.begin() + std::rand() % boxes.size());
    } else {
      boxes[std::rand() % boxes.size()].center.y() += 0.01;
    }
    const Environment next("c", version, static_cast<std::int64_t>(version) * 1000, boxes);
    rebuilt = apply(rebuilt, diff(current, next));
    ASSERT_EQ(rebuilt, next) << "version " << version;
    current = next;
  }
}

}  // namespace
}  // namespace cellmap
