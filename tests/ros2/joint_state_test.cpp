// SPDX-License-Identifier: Apache-2.0
// JointState names matched to the robot's joints: any order, other joints ignored, gaps refused.
#include "cellmap/ros2/joint_state.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "cellmap/common/error.hpp"

namespace cellmap::ros2 {
namespace {

const std::vector<std::string> kRobot{"joint_1", "joint_2", "joint_3"};

std::string refusal(const std::vector<std::string>& names, const std::vector<double>& positions) {
  try {
    (void)in_robot_order(names, positions, kRobot);
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

TEST(JointStateTest, NamesInAnyOrderWithOtherJointsIgnored) {
  const std::vector<double> q =
      in_robot_order({"gripper_finger", "joint_3", "joint_1", "joint_2"}, {0.04, 3.0, 1.0, 2.0}, kRobot);
  EXPECT_EQ(q, (std::vector<double>{1.0, 2.0, 3.0}));
}

TEST(JointStateTest, IncompleteOrBrokenSamplesAreRefused) {
  EXPECT_EQ(refusal({"joint_1", "joint_2"}, {1.0, 2.0}), "no position for joint 'joint_3'");
  EXPECT_EQ(refusal({"joint_1", "joint_2", "joint_3"}, {1.0, 2.0}), "3 names but 2 positions");
  EXPECT_EQ(refusal({"joint_1", "joint_1", "joint_2", "joint_3"}, {1, 1, 2, 3}),
            "joint 'joint_1' given twice");
  EXPECT_EQ(refusal({"joint_1", "joint_2", "joint_3"}, {1.0, std::numeric_limits<double>::quiet_NaN(), 3.0}),
            "joint 'joint_2' position is not finite");
  EXPECT_EQ(refusal({"joint_1", "joint_2", "joint_3\n"}, {1, 2, 3}), "no position for joint 'joint_3'");
  EXPECT_EQ(refusal(std::vector<std::string>(1025, "joint_1"), std::vector<double>(1025, 0.0)),
            "1025 names, more than 1024");
}

}  // namespace
}  // namespace cellmap::ros2
