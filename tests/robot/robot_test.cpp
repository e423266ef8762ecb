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

}  // namespace
}  // namespace cellmap
