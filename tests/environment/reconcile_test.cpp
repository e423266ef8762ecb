// SPDX-License-Identifier: Apache-2.0
#include "cellmap/environment/reconcile.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

Box make_box(std::uint64_t id, Eigen::Vector3d center, Eigen::Vector3d half, double yaw = 0.0) {
  Box box;
  box.id = id;
  box.center = center;
  box.half_extents = half;
  box.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  box.points = 100;
  return box;
}

// A table (id 1) with one object on it (id 2).
std::vector<Box> table_scene() {
  return {make_box(1, {1.5, 1.0, 0.375}, {1.5, 1.0, 0.025}), make_box(2, {0.5, 0.5, 0.5}, {0.1, 0.1, 0.1})};
}

TEST(ReconcileTest, BoundsOfRotatedBox) {
  const Region r = bounds_of(make_box(1, {0, 0, 0}, {1, 1, 0.5}, M_PI / 4));
  EXPECT_NEAR(r.max.x(), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(r.max.z(), 0.5, 1e-12);
  EXPECT_NEAR(r.min.y(), -std::sqrt(2.0), 1e-12);
}

TEST(ReconcileTest, NoiseWithinToleranceGivesNoDelta) {
  const auto previous = table_scene();
  // Surface voxels of the object flickered.
  const auto scope = boxes_touched(previous, {previous[1].center + Eigen::Vector3d(0.09, 0, 0.09)});
  ASSERT_EQ(scope, std::vector<std::uint64_t>{2});
  Box jittered = previous[1];
  jittered.center.x() += 0.005;
  jittered.half_extents.z() += 0.004;
  const Reconciled out = reconcile(previous, scope, {jittered}, 3);
  EXPECT_FALSE(out.changed());
  ASSERT_EQ(out.boxes.size(), 2u);
  EXPECT_EQ(out.boxes[1].center, previous[1].center);  // the old value is kept exactly
  EXPECT_EQ(out.next_id, 3u);
}

TEST(ReconcileTest, BoxesTouchedNeedTheirShareOfChangedVoxels) {
  std::vector<Box> previous = table_scene();
  previous[1].points = 40;
  const Eigen::Vector3d inside = previous[1].center;
  const std::vector<Eigen::Vector3d> three(3, inside), four(4, inside);
  EXPECT_EQ(boxes_touched(previous, three), std::vector<std::uint64_t>{2});  // any one suffices by default
  EXPECT_TRUE(boxes_touched(previous, three, 0.1).empty());                  // 3 < 10 % of 40
  EXPECT_EQ(boxes_touched(previous, four, 0.1), std::vector<std::uint64_t>{2});
}

TEST(ReconcileTest, AddedObjectGetsAFreshIdAndTablePatchIsRedundant) {
  const auto previous = table_scene();
  const Box added = make_box(0, {2.0, 1.2, 0.55}, {0.15, 0.1, 0.15});
  // The new object's voxels, down to the layer right above the table top (z = 0.4): the table is untouched.
  const auto scope = boxes_touched(previous, {added.center, Eigen::Vector3d(2.0, 1.2, 0.41)});
  EXPECT_TRUE(scope.empty());
  // Re-segmenting region + margin also yields a patch of the table surface beside the new object.
  const Box table_patch = make_box(0, {2.0, 1.2, 0.38}, {0.2, 0.15, 0.01});
  const Reconciled out = reconcile(previous, scope, {added, table_patch}, 3);
  ASSERT_EQ(out.added.size(), 1u);
  EXPECT_EQ(out.added[0].id, 3u);
  EXPECT_EQ(out.added[0].center, added.center);
  EXPECT_TRUE(out.modified.empty());
  EXPECT_TRUE(out.removed.empty());
  EXPECT_EQ(out.boxes.size(), 3u);
  EXPECT_EQ(out.next_id, 4u);
}

TEST(ReconcileTest, VanishedObjectIsRemovedAndItsIdNeverReused) {
  const auto previous = table_scene();
  const auto scope = boxes_touched(previous, {previous[1].center});
  const Reconciled removed = reconcile(previous, scope, {}, 3);
  EXPECT_EQ(removed.removed, std::vector<std::uint64_t>{2});
  ASSERT_EQ(removed.boxes.size(), 1u);
  EXPECT_EQ(removed.boxes[0].id, 1u);
  // The object comes back: it is a new object with a new id.
  const Reconciled back = reconcile(removed.boxes, {}, {previous[1]}, removed.next_id);
  ASSERT_EQ(back.added.size(), 1u);
  EXPECT_EQ(back.added[0].id, 3u);
}

TEST(ReconcileTest, SmallMoveKeepsTheIdLargeMoveIsRemoveAndAdd) {
  const auto previous = table_scene();
  Box nudged = previous[1];
  nudged.center.x() += 0.06;
  // The voxels the object left at its -x side.
  const auto scope = boxes_touched(previous, {previous[1].center - Eigen::Vector3d(0.09, 0, 0)});
  const Reconciled small = reconcile(previous, scope, {nudged}, 3);
  ASSERT_EQ(small.modified.size(), 1u);
  EXPECT_EQ(small.modified[0].id, 2u);
  EXPECT_EQ(small.modified[0].center, nudged.center);
  EXPECT_TRUE(small.added.empty() && small.removed.empty());

  Box far = previous[1];
  far.center.x() += 1.0;
  const auto scope_far = boxes_touched(previous, {previous[1].center, far.center});
  const Reconciled large = reconcile(previous, scope_far, {far}, 3);
  EXPECT_EQ(large.removed, std::vector<std::uint64_t>{2});
  ASSERT_EQ(large.added.size(), 1u);
  EXPECT_EQ(large.added[0].id, 3u);
}

TEST(ReconcileTest, SplitObjectKeepsIdOnTheBiggerPart) {
  const auto previous = table_scene();
  const Box left = make_box(0, {0.45, 0.5, 0.5}, {0.05, 0.1, 0.1});
  const Box right = make_box(0, {0.58, 0.5, 0.5}, {0.02, 0.1, 0.1});
  const auto scope = boxes_touched(previous, {previous[1].center});
  const Reconciled out = reconcile(previous, scope, {right, left}, 3);
  ASSERT_EQ(out.modified.size(), 1u);
  EXPECT_EQ(out.modified[0].id, 2u);
  EXPECT_EQ(out.modified[0].center, left.center);
  ASSERT_EQ(out.added.size(), 1u);
  EXPECT_EQ(out.added[0].center, right.center);
}

TEST(ReconcileTest, SliverInsideALargerNewBoxIsDropped) {
  const auto previous = table_scene();
  const Box added = make_box(0, {2.12, 0.45, 0.91}, {0.12, 0.11, 0.15});
  const Box sliver = make_box(0, {2.22, 0.45, 0.91}, {0.02, 0.11, 0.13});  // one face, inside `added`
  const Reconciled out = reconcile(previous, {}, {sliver, added}, 3);
  ASSERT_EQ(out.added.size(), 1u);
  EXPECT_EQ(out.added[0].center, added.center);
}

TEST(ReconcileTest, RejectsAnIdCounterThatCouldReuseIds) {
  EXPECT_THROW((void)reconcile(table_scene(), {}, {}, 2), Error);
}

}  // namespace
}  // namespace cellmap
