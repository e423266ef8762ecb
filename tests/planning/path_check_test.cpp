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

}  // namespace
}  // namespace cellmap::planning
