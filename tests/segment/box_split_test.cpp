// SPDX-License-Identifier: Apache-2.0
#include "cellmap/segment/box_split.hpp"

#include <gtest/gtest.h>

#include <map>

#include "cellmap/common/error.hpp"
#include "scenes.hpp"

namespace cellmap {
namespace {

const Eigen::Matrix3d kI = Eigen::Matrix3d::Identity();

Segments one_segment(const test::Scene& scene) {
  Segments s;
  s.label.assign(scene.points.size(), 0);
  s.count = 1;
  return s;
}

// For each segment: how many points of each object it holds.
std::map<int, std::map<int, int>> objects_per_segment(const test::Scene& scene, const Segments& s) {
  std::map<int, std::map<int, int>> out;
  for (std::size_t i = 0; i < s.label.size(); ++i) ++out[s.label[i]][scene.object[i]];
  return out;
}

BoxSplitParams params() {
  return test::split_params();
}

Segments split(const test::Scene& scene, std::size_t* count = nullptr) {
  return split_by_free_space(scene.points, compute_neighbourhoods(scene.points, 12, false),
                             one_segment(scene), scene.viewpoint().cast<double>(), params(), count);
}

TEST(BoxSplitTest, APostOnAPlateIsCutWhereTheCutFreesSpace) {
  // A fixture: a 50 × 30 × 5 cm plate with an 8 × 8 × 30 cm post on it, seen from above. One box would block
  // the whole 50 × 30 × 35 cm around them.
  test::Scene scene(Eigen::Vector3f(0.3f, -0.5f, 1.5f));
  scene.add_box({0, 0, 0.025}, {0.25, 0.15, 0.025}, kI);
  scene.add_box({0.1, 0, 0.2}, {0.04, 0.04, 0.15}, kI);
  std::size_t split_count = 0;
  const Segments parts = split(scene, &split_count);
  EXPECT_EQ(split_count, 1u);
  ASSERT_EQ(parts.count, 2);
  // One part is the plate, the other the post (the post's foot row may go either way).
  for (const auto& [segment, objects] : objects_per_segment(scene, parts)) {
    int most = 0, total = 0;
    for (const auto& [object, n] : objects) most = std::max(most, n), total += n;
    EXPECT_GT(most, 0.97 * total) << "segment " << segment;
  }
}

TEST(BoxSplitTest, ABoxSeenAsTopAndOneSideStaysWhole) {
  // The top and one side make an L in cross-section; cutting it would only cut away the hidden inside.
  test::Scene scene(Eigen::Vector3f(0.8f, 0.0f, 1.0f));
  scene.add_box({0, 0, 0.15}, {0.2, 0.15, 0.15}, kI);
  const Segments parts = split(scene);
  EXPECT_EQ(parts.count, 1);
}

TEST(BoxSplitTest, PalletsMergedWithTheTableUnderThemAreCutOff) {
  // A table top with two boxes on opposite corners, all in one segment: no single cut separates the three,
  // but a cut above the table top leaves the two boxes as separate pieces.
  test::Scene scene(Eigen::Vector3f(0.0f, 0.0f, 1.6f));
  scene.add_box({0, 0, -0.02}, {0.5, 0.4, 0.02}, kI);
  scene.add_box({-0.3, -0.2, 0.07}, {0.15, 0.12, 0.07}, kI);
  scene.add_box({0.3, 0.2, 0.07}, {0.15, 0.12, 0.07}, kI);
  const Segments parts = split(scene);
  EXPECT_EQ(parts.count, 3);
  for (const auto& [segment, objects] : objects_per_segment(scene, parts)) {
    int most = 0, total = 0;
    for (const auto& [object, n] : objects) most = std::max(most, n), total += n;
    EXPECT_GT(most, 0.95 * total) << "segment " << segment;
  }
}

TEST(BoxSplitTest, BoxesStackedFlushJoinAndDistantOnesDoNot) {
  // Two equal boxes stacked flush (one box around both blocks nothing more) and a third 30 cm away.
  test::Scene scene(Eigen::Vector3f(0.4f, -0.6f, 1.4f));
  scene.add_box({0, 0, 0.1}, {0.15, 0.1, 0.1}, kI);
  scene.add_box({0, 0, 0.3}, {0.15, 0.1, 0.1}, kI);
  scene.add_box({0.6, 0, 0.1}, {0.15, 0.1, 0.1}, kI);
  Segments by_object;
  by_object.count = 3;
  for (int object : scene.object) by_object.label.push_back(object - 1);
  std::size_t joins = 0;
  const Segments joined =
      join_by_free_space(scene.points, by_object, scene.viewpoint().cast<double>(), params(), &joins);
  EXPECT_EQ(joins, 1u);
  ASSERT_EQ(joined.count, 2);
  std::map<int, int> segment_of;  // object → its segment (each object whole in one)
  for (std::size_t i = 0; i < scene.points.size(); ++i) segment_of[scene.object[i]] = joined.label[i];
  for (const auto& [segment, objects] : objects_per_segment(scene, joined)) {
    for (const auto& [object, n] : objects) EXPECT_EQ(segment_of[object], segment) << "object " << object;
  }
  EXPECT_EQ(segment_of[1], segment_of[2]);
  EXPECT_NE(segment_of[1], segment_of[3]);
  // Joining off: nothing changes.
  BoxSplitParams never = params();
  never.max_growth = 0;
  EXPECT_EQ(join_by_free_space(scene.points, by_object, scene.viewpoint().cast<double>(), never).count, 3);
}

TEST(BoxSplitTest, RefusesInvalidParameters) {
  const test::Scene scene(Eigen::Vector3f(0, 0, 1));
  BoxSplitParams bad = params();
  bad.min_gain = 0;
  EXPECT_THROW((void)split_by_free_space(scene.points, {}, {}, {0, 0, 1}, bad), Error);
  bad = params();
  bad.angular_step = 0;
  EXPECT_THROW((void)join_by_free_space(scene.points, {}, {0, 0, 1}, bad), Error);
}

}  // namespace
}  // namespace cellmap
