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

// A planar two-link arm (links 1 m and 0.5 m, both joints about z) plus a fixed tool flange: the textbook FK
// x = l1 cos q1 + l2 cos(q1 + q2), y = l1 sin q1 + l2 sin(q1 + q2).
constexpr const char* kTwoLinkArm = R"(<?xml version="1.0"?>
<robot name="two_link">
  <link name="base"/>
  <link name="upper"/>
  <link name="fore"/>
  <link name="flange"/>
  <link name="camera"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/>
    <origin xyz="1 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="flange_mount" type="fixed">
    <parent link="fore"/><child link="flange"/>
    <origin xyz="0.5 0 0" rpy="0 0 0"/>
  </joint>
  <joint name="camera_mount" type="fixed">
    <parent link="base"/><child link="camera"/>
    <origin xyz="0 0 2" rpy="0 0 0"/>
  </joint>
</robot>)";

TEST(RobotTest, UrdfChainMatchesTextbookForwardKinematics) {
  Eigen::Isometry3d X_C_root = Eigen::Isometry3d::Identity();
  X_C_root.translation() = Eigen::Vector3d(2, 1, 0);
  const Robot robot = Robot::from_urdf_string(kTwoLinkArm, "flange", X_C_root);
  EXPECT_EQ(robot.dof(), 2);
  EXPECT_EQ(robot.joint_names(), (std::vector<std::string>{"shoulder", "elbow"}));
  EXPECT_EQ(robot.link_names(), (std::vector<std::string>{"base", "upper", "fore", "flange"}));
  EXPECT_DOUBLE_EQ(robot.limits()[1].lower, -2.0);
  for (const auto& [q1, q2] : {std::pair{0.0, 0.0}, {0.7, -1.1}, {-2.5, 1.9}}) {
    const Eigen::Isometry3d X_CE = robot.tool_pose(Eigen::Vector2d(q1, q2));
    const Eigen::Vector3d expected(2 + std::cos(q1) + 0.5 * std::cos(q1 + q2),
                                   1 + std::sin(q1) + 0.5 * std::sin(q1 + q2), 0.3);
    EXPECT_TRUE(X_CE.translation().isApprox(expected, 1e-12)) << q1 << " " << q2;
    EXPECT_NEAR(Eigen::AngleAxisd(X_CE.linear()).angle(), std::abs(std::remainder(q1 + q2, 2 * M_PI)), 1e-12);
  }
}

TEST(RobotTest, UrdfErrorsNameTheSource) {
  try {
    (void)Robot::from_urdf_string(kTwoLinkArm, "gripper", Eigen::Isometry3d::Identity(), "arm.urdf");
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "arm.urdf: tool link 'gripper' is not in the URDF");
  }
  try {
    (void)Robot::from_urdf_string("<robot><oops", "flange", Eigen::Isometry3d::Identity(), "bad.urdf");
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "bad.urdf: not a valid URDF robot description");
  }
  EXPECT_THROW((void)Robot::from_urdf_file("/nonexistent/arm.urdf", "flange"), Error);
}

}  // namespace
}  // namespace cellmap
