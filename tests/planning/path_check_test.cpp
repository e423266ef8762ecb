// SPDX-License-Identifier: Apache-2.0
#include "cellmap/planning/path_check.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"
#include "cellmap/planning/bspline.hpp"

namespace cellmap::planning {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

VectorXd v3(double x, double y, double z) {
  return Vector3d(x, y, z);
}

TEST(BSplineTest, CubicWithFourPointsIsTheBezierCurve) {
  const BSplinePath path({v3(0, 0, 0), v3(1, 2, 0), v3(3, 2, 1), v3(4, 0, 0)});
  EXPECT_EQ(path.degree(), 3);
  EXPECT_LT((path.at(0.0) - v3(0, 0, 0)).norm(), 1e-15);
  EXPECT_LT((path.at(1.0) - v3(4, 0, 0)).norm(), 1e-15);
  // Bernstein weights at t = 0.5: (1, 3, 3, 1) / 8.
  EXPECT_LT((path.at(0.5) - (v3(0, 0, 0) + 3 * v3(1, 2, 0) + 3 * v3(3, 2, 1) + v3(4, 0, 0)) / 8).norm(),
            1e-15);
  // t = 0.25: ((3/4)^3, 3 (3/4)^2 (1/4), 3 (3/4) (1/4)^2, (1/4)^3).
  const VectorXd expected =
      27.0 / 64 * v3(0, 0, 0) + 27.0 / 64 * v3(1, 2, 0) + 9.0 / 64 * v3(3, 2, 1) + 1.0 / 64 * v3(4, 0, 0);
  EXPECT_LT((path.at(0.25) - expected).norm(), 1e-15);
}

TEST(BSplineTest, ClampedUniformWithMorePoints) {
  // Seven control points: 4 uniform spans; a straight, evenly spaced control polygon gives a path on the line
  // that starts and ends at the end points and stays inside the control polygon's hull.
  std::vector<VectorXd> points;
  for (int i = 0; i < 7; ++i) points.push_back(v3(i, 2 * i, 0));
  const BSplinePath path(points);
  const auto samples = path.sample(11);
  ASSERT_EQ(samples.size(), 11u);
  EXPECT_LT((samples.front() - points.front()).norm(), 1e-15);
  EXPECT_LT((samples.back() - points.back()).norm(), 1e-12);
  for (const VectorXd& p : samples) {
    EXPECT_NEAR(p.y(), 2 * p.x(), 1e-12);
    EXPECT_GE(p.x(), -1e-12);
    EXPECT_LE(p.x(), 6 + 1e-12);
  }
  // Symmetric control polygon → symmetric path: z(0.5) is the middle control point here.
  EXPECT_LT((path.at(0.5) - points[3]).norm(), 1e-12);
  // Two points: a straight line.
  EXPECT_LT((BSplinePath({v3(0, 0, 0), v3(2, 0, 0)}).at(0.25) - v3(0.5, 0, 0)).norm(), 1e-15);
}

TEST(BSplineTest, RefusesBadControlPoints) {
  EXPECT_THROW(BSplinePath({v3(0, 0, 0)}), Error);
  EXPECT_THROW(BSplinePath({v3(0, 0, 0), VectorXd::Zero(2)}), Error);
  EXPECT_THROW(BSplinePath({v3(0, 0, 0), v3(NAN, 0, 0)}), Error);
  EXPECT_THROW((void)BSplinePath({v3(0, 0, 0), v3(1, 0, 0)}).sample(0), Error);
}

// A gantry carrying a 0.2 m cube on its ram travels along y at x = 1; one obstacle sits at y = 2.
struct Scene {
  collision::RobotBoxes robot{Robot::gantry(Vector3d(-5, -5, -5), Vector3d(5, 5, 5)),
                              {{"ram", Eigen::Isometry3d::Identity(), Vector3d(0.1, 0.1, 0.1)}}};
  std::vector<collision::Obb> environment{collision::Obb(Vector3d(1.0, 2.0, 0.0), Vector3d(0.2, 0.2, 0.2)),
                                          collision::Obb(Vector3d(4.0, 4.0, 0.0), Vector3d(0.2, 0.2, 0.2))};
  collision::BoxTree tree{environment};
};

TEST(PathCheckTest, ConstraintCountAndClosestCheckpoint) {
  const Scene scene;
  // Straight line at x = 1.45 from y = 0 to y = 4: closest approach 1.45 − 0.1 − 1.2 = 0.15 at y = 2.
  const BSplinePath path({v3(1.45, 0, 0), v3(1.45, 4.0 / 3, 0), v3(1.45, 8.0 / 3, 0), v3(1.45, 4, 0)});
  const collision::ConstraintSet set = path_constraints(scene.robot, path, 21, scene.environment);
  EXPECT_EQ(set.n_constr(), 1u * 2u * 21u);
  ASSERT_EQ(set.entries.size(), set.n_constr());
  EXPECT_NEAR(set.min_distance(), 0.15, 1e-12);
  EXPECT_FALSE(path_blocked(scene.robot, path, 21, scene.environment, scene.tree, 0.1).blocked);
  const Blocking blocking = path_blocked(scene.robot, path, 21, scene.environment, scene.tree, 0.2);
  EXPECT_TRUE(blocking.blocked);
  EXPECT_EQ(blocking.env_box, 0);
  EXPECT_LT(blocking.distance, 0.2);
}

TEST(PathCheckTest, BlockedPathReportsTheFirstCheckpoint) {
  const Scene scene;
  const BSplinePath path({v3(1, 0, 0), v3(1, 4, 0)});  // straight through the obstacle
  const Blocking blocking = path_blocked(scene.robot, path, 41, scene.environment, scene.tree, 0.0);
  ASSERT_TRUE(blocking.blocked);
  // Checkpoint k is at y = 0.1 k; the cube (half 0.1) first overlaps the obstacle (from y = 1.8) at y > 1.7.
  EXPECT_EQ(blocking.checkpoint, 18);
  EXPECT_LT(blocking.distance, 0.0);
  // With a margin of 0.25 m the first violation comes earlier: gap 1.8 − 0.1 − y < 0.25 ⇒ y > 1.45.
  EXPECT_EQ(path_blocked(scene.robot, path, 41, scene.environment, scene.tree, 0.25).checkpoint, 15);
  EXPECT_THROW((void)path_blocked(scene.robot, BSplinePath({VectorXd::Zero(2), VectorXd::Ones(2)}), 3,
                                  scene.environment, scene.tree, 0.0),
               Error);
}

Box cube_at(std::uint64_t id, const Vector3d& center, BoxSpace space) {
  Box box;
  box.id = id;
  box.center = center;
  box.half_extents = Vector3d(0.2, 0.2, 0.2);
  box.space = space;
  return box;
}

// The scene's gantry on the straight line x = 1 from y = 0 to y = 4, checkpoint k at y = 0.1 k: its cube
// (half 0.1) first overlaps a box whose near face is at y = c − 0.2 at the checkpoint with 0.1 k + 0.1 > c −
// 0.2. An unknown box (id 7) sits at y = 2, an obstacle (id 9) behind it at y = 3.05, listed first.
struct UnknownScene {
  Scene scene;
  BSplinePath path{{v3(1, 0, 0), v3(1, 4, 0)}};
  std::vector<Box> boxes{cube_at(9, Vector3d(1, 3.05, 0), BoxSpace::kOccupied),
                         cube_at(7, Vector3d(1, 2, 0), BoxSpace::kUnknown)};
};

TEST(PathCheckTest, UnknownBoxBlocksByDefaultAndSaysSo) {
  const UnknownScene s;
  const PathEnvironment environment(s.boxes);
  EXPECT_EQ(environment.obbs().size(), 2u);
  EXPECT_EQ(environment.ignored(), 0u);
  const Blocking blocking = path_blocked(s.scene.robot, s.path, 41, environment, 0.0);
  ASSERT_TRUE(blocking.blocked);
  EXPECT_EQ(blocking.box_id, 7u);
  EXPECT_EQ(blocking.space, BoxSpace::kUnknown);
  EXPECT_EQ(blocking.env_box, 1);
  EXPECT_EQ(blocking.checkpoint, 18);  // y = 1.8: the cube reaches 1.9, 0.1 into the box's face at 1.8
  EXPECT_DOUBLE_EQ(blocking.t, 18.0 / 40.0);
  EXPECT_NEAR(blocking.distance, -0.1, 1e-12);
  // The path runs into the unknown box's near face.
  EXPECT_NEAR(blocking.point.y(), 1.8, 1e-12);
  EXPECT_TRUE(s.boxes[1].contains(blocking.point, 1e-12));
}

TEST(PathCheckTest, IgnoringUnknownSpaceFreesThePathButObstaclesStillBlock) {
  const UnknownScene s;
  const PathEnvironment only_unknown({s.boxes[1]}, PathCheckOptions{true});
  EXPECT_TRUE(only_unknown.obbs().empty());
  EXPECT_EQ(only_unknown.ignored(), 1u);
  EXPECT_FALSE(path_blocked(s.scene.robot, s.path, 41, only_unknown, 0.0).blocked);
  // The margin reaches no further than the boxes' faces either.
  EXPECT_FALSE(path_blocked(s.scene.robot, s.path, 41, only_unknown, 0.5).blocked);

  // Past the ignored unknown box, the obstacle behind it blocks: first at y = 2.8 (cube up to 2.9, 0.05 past
  // the face at 2.85).
  const PathEnvironment both(s.boxes, PathCheckOptions{true});
  const Blocking blocking = path_blocked(s.scene.robot, s.path, 41, both, 0.0);
  ASSERT_TRUE(blocking.blocked);
  EXPECT_EQ(blocking.box_id, 9u);
  EXPECT_EQ(blocking.space, BoxSpace::kOccupied);
  EXPECT_EQ(blocking.env_box, 0);
  EXPECT_EQ(blocking.checkpoint, 28);
  EXPECT_DOUBLE_EQ(blocking.t, 0.7);
  EXPECT_NEAR(blocking.distance, -0.05, 1e-12);
  EXPECT_NEAR(blocking.point.y(), 2.85, 1e-12);

  // The constraint vector leaves the ignored box out too: one environment box.
  EXPECT_EQ(path_constraints(s.scene.robot, s.path, 41, both.obbs()).n_env, 1);
}

TEST(PathCheckTest, BareBoxesBlockAsObstaclesWithoutAnId) {
  const Scene scene;
  const Blocking blocking = path_blocked(scene.robot, BSplinePath({v3(1, 0, 0), v3(1, 4, 0)}), 41,
                                         scene.environment, scene.tree, 0.0);
  ASSERT_TRUE(blocking.blocked);
  EXPECT_EQ(blocking.box_id, 0u);
  EXPECT_EQ(blocking.space, BoxSpace::kOccupied);
  EXPECT_DOUBLE_EQ(blocking.t, 0.45);
}

}  // namespace
}  // namespace cellmap::planning
