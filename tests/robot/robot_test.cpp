// SPDX-License-Identifier: Apache-2.0
#include "cellmap/robot/robot.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

// Tool looking straight down: tool z along cell −z.
Eigen::Isometry3d looking_down(const Eigen::Vector3d& p) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  X.translation() = p;
  return X;
}

TEST(RobotTest, GantryToolPoseIsTranslationTimesZeroPose) {
  const Eigen::Isometry3d X_CE_zero = looking_down({0.1, 0.2, 1.5});
  const Robot robot = Robot::gantry({0, 0, -0.5}, {3, 2, 0}, X_CE_zero);
  EXPECT_EQ(robot.dof(), 3);
  EXPECT_EQ(robot.link_names(), (std::vector<std::string>{"base", "bridge", "carriage", "ram"}));
  const Eigen::Vector3d q(1.0, 0.5, -0.25);
  const Eigen::Isometry3d X_CE = robot.tool_pose(q);
  EXPECT_TRUE(X_CE.translation().isApprox(Eigen::Vector3d(1.1, 0.7, 1.25), 1e-12));
  EXPECT_TRUE(X_CE.linear().isApprox(X_CE_zero.linear(), 1e-12));
  const auto poses = robot.link_poses(q);
  ASSERT_EQ(poses.size(), 4u);
  EXPECT_TRUE(poses[0].isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(poses[1].translation().isApprox(Eigen::Vector3d(1.1, 0.2, 1.5), 1e-12));  // bridge: x only
  EXPECT_TRUE(poses[2].translation().isApprox(Eigen::Vector3d(1.1, 0.7, 1.5), 1e-12));  // carriage: x, y
  EXPECT_TRUE(robot.within_limits(q));
  EXPECT_FALSE(robot.within_limits(Eigen::Vector3d(3.5, 0, 0)));
  EXPECT_FALSE(robot.within_limits(Eigen::Vector2d(0, 0)));
}

TEST(RobotTest, GantryRejectsBadRangesAndJointVectors) {
  EXPECT_THROW((void)Robot::gantry({1, 0, 0}, {0, 1, 1}), Error);
  EXPECT_THROW((void)Robot::gantry({0, 0, 0}, {NAN, 1, 1}), Error);
  const Robot robot = Robot::gantry({0, 0, 0}, {1, 1, 1});
  EXPECT_THROW((void)robot.tool_pose(Eigen::Vector2d(0, 0)), Error);
  EXPECT_THROW((void)robot.tool_pose(Eigen::Vector3d(0, NAN, 0)), Error);
}

TEST(RobotTest, GantryPartsMoveWithTheirAxes) {
  const Eigen::Isometry3d X_CE_zero = looking_down({0.0, 0.0, 2.4});
  const Eigen::Vector3d lower(0, 0, -0.6), upper(3, 2, 0);
  const GantryParts parts = GantryParts::fitting(lower, upper, X_CE_zero);
  const Robot robot = Robot::gantry(lower, upper, X_CE_zero, parts);
  ASSERT_EQ(robot.shapes().size(), 3u);
  EXPECT_EQ(robot.shape_links(), (std::vector<int>{1, 2, 3}));
  // The ram stands on the flange and reaches the carriage's top even at the lowest z.
  EXPECT_NEAR(parts.ram.center.z() - parts.ram.half_extents.z(), 2.4, 1e-12);
  EXPECT_NEAR(parts.ram.center.z() + parts.ram.half_extents.z() - 0.6,
              parts.carriage.center.z() + parts.carriage.half_extents.z(), 1e-12);
  // At q = 0 the shapes are where the parts say; each then moves with its axes only.
  const std::vector<Eigen::Isometry3d> at_zero = robot.shape_poses(Eigen::Vector3d::Zero());
  EXPECT_LT((at_zero[0].translation() - parts.bridge.center).norm(), 1e-12);
  EXPECT_LT((at_zero[2].translation() - parts.ram.center).norm(), 1e-12);
  const Eigen::Vector3d q(1.0, 0.5, -0.25);
  const std::vector<Eigen::Isometry3d> moved = robot.shape_poses(q);
  EXPECT_LT((moved[0].translation() - parts.bridge.center - Eigen::Vector3d(1.0, 0, 0)).norm(), 1e-12);
  EXPECT_LT((moved[1].translation() - parts.carriage.center - Eigen::Vector3d(1.0, 0.5, 0)).norm(), 1e-12);
  EXPECT_LT((moved[2].translation() - parts.ram.center - q).norm(), 1e-12);
  // The boxes keep their cell-aligned sizes although the link frames look down.
  const std::vector<LinkBox> boxes = robot.shape_boxes();
  const Eigen::Vector3d bridge_in_cell = (at_zero[0].linear() * boxes[0].half_extents).cwiseAbs();
  EXPECT_LT((bridge_in_cell - parts.bridge.half_extents).norm(), 1e-12);
  EXPECT_EQ(robot.triangle_count(), 0u);
}

TEST(RobotTest, ShapesMustSitOnChainLinksWithPositiveSizes) {
  const Robot robot = Robot::gantry({0, 0, 0}, {1, 1, 1});
  EXPECT_TRUE(robot.shapes().empty());
  try {
    (void)robot.with_shapes({{"wrist", Eigen::Isometry3d::Identity(), SphereShape{0.1}}});
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "robot shape 0 (link 'wrist'): the robot has no such link");
  }
  EXPECT_THROW((void)robot.with_shapes({{"ram", Eigen::Isometry3d::Identity(), CylinderShape{0.1, -1}}}),
               Error);
  EXPECT_THROW((void)robot.with_shapes({{"ram", Eigen::Isometry3d::Identity(), MeshShape{}}}), Error);
  auto open_mesh = std::make_shared<TriangleMesh>();
  open_mesh->vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  open_mesh->triangles = {{0, 1, 3}};
  EXPECT_THROW((void)robot.with_shapes({{"ram", Eigen::Isometry3d::Identity(), MeshShape{open_mesh}}}),
               Error);
  open_mesh->triangles = {{0, 1, 2}};
  const Robot with_mesh = robot.with_shapes({{"ram", Eigen::Isometry3d::Identity(), MeshShape{open_mesh}}});
  EXPECT_EQ(with_mesh.triangle_count(), 1u);
  EXPECT_LT((with_mesh.shape_boxes()[0].half_extents - Eigen::Vector3d(0.5, 0.5, 0)).norm(), 1e-12);
}

}  // namespace
}  // namespace cellmap
