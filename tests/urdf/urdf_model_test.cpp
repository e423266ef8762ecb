// SPDX-License-Identifier: Apache-2.0
#include "cellmap/urdf/urdf_model.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "cellmap/common/error.hpp"
#include "support/test_support.hpp"

namespace cellmap {
namespace {

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

TEST(UrdfModelTest, ChainMatchesTextbookForwardKinematics) {
  Eigen::Isometry3d X_C_root = Eigen::Isometry3d::Identity();
  X_C_root.translation() = Eigen::Vector3d(2, 1, 0);
  const Robot robot = UrdfModel::parse(kTwoLinkArm).chain("flange", X_C_root);
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

TEST(UrdfModelTest, ErrorsNameTheSource) {
  try {
    (void)UrdfModel::parse(kTwoLinkArm, "arm.urdf").chain("gripper");
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "arm.urdf: tool link 'gripper' is not in the URDF");
  }
  try {
    (void)UrdfModel::parse("<robot><oops", "bad.urdf").chain("flange");
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "bad.urdf: not a valid URDF robot description");
  }
  EXPECT_THROW((void)UrdfModel::load("/nonexistent/arm.urdf").chain("flange"), Error);
}

// Found while fuzzing (fuzz_urdf): urdfdom accepts joints that close a loop away from the root, and the walk
// from the tool link up to the root never ended; a link that is its own parent is refused by urdfdom.
TEST(UrdfModelTest, LoopsAreRefused) {
  const std::string loop = test::fuzz_regression("urdf", "loop_away_from_root.urdf");
  EXPECT_EQ(test::one_line_error_of([&] { (void)UrdfModel::load(loop).chain("tool0"); }),
            loop + ": the links from 'tool0' up to the root form a loop");
  const std::string self = test::fuzz_regression("urdf", "self_parented_link.urdf");
  EXPECT_EQ(test::one_line_error_of([&] { (void)UrdfModel::load(self).chain("tool0"); }),
            self + ": not a valid URDF robot description");
}

}  // namespace
}  // namespace cellmap
