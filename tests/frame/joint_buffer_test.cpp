// SPDX-License-Identifier: Apache-2.0
// Joint-state input: joints interpolated to frame times, forward kinematics at that time, the payload of the
// nearer sample, and the drop-without-bracketing-samples rule.
#include "cellmap/frame/joint_buffer.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

// A planar arm: shoulder and elbow about z, 1 m and 0.5 m links; the textbook FK of its flange.
Robot planar_arm() {
  Robot::ChainJoint shoulder{"shoulder",
                             "upper",
                             Eigen::Isometry3d::Identity(),
                             Robot::JointType::kRevolute,
                             Eigen::Vector3d::UnitZ(),
                             {-3, 3}};
  Robot::ChainJoint elbow{"elbow",
                          "fore",
                          Eigen::Isometry3d(Eigen::Translation3d(1, 0, 0)),
                          Robot::JointType::kRevolute,
                          Eigen::Vector3d::UnitZ(),
                          {-3, 3}};
  Robot::ChainJoint flange{"",
                           "flange",
                           Eigen::Isometry3d(Eigen::Translation3d(0.5, 0, 0)),
                           Robot::JointType::kFixed,
                           Eigen::Vector3d::UnitZ(),
                           {}};
  return Robot::serial("base", {shoulder, elbow, flange});
}

Eigen::Vector3d flange_at(double q1, double q2) {
  return {std::cos(q1) + 0.5 * std::cos(q1 + q2), std::sin(q1) + 0.5 * std::sin(q1 + q2), 0};
}

TEST(JointBufferTest, JointsAreInterpolatedLinearlyAndPosedByForwardKinematics) {
  JointBuffer buffer(planar_arm(), 0.01);
  Payload carton;
  carton.half_extents = Eigen::Vector3d(0.1, 0.1, 0.1);
  buffer.push({1.008, Eigen::Vector2d(0.8, -0.4), carton});
  buffer.push({1.000, Eigen::Vector2d(0.0, 0.4), std::nullopt});  // out of order
  const JointBuffer::Result a_quarter = buffer.at(1.002);
  ASSERT_EQ(a_quarter.status, PoseLookup::kFound);
  EXPECT_LT((a_quarter.state.q - Eigen::Vector2d(0.2, 0.2)).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(a_quarter.state.stamp, 1.002);
  // Interpolated in joint space: the flange is on the arm's true path, not on the chord between the samples.
  EXPECT_LT((a_quarter.X_CE().translation() - flange_at(0.2, 0.2)).norm(), 1e-12);
  ASSERT_EQ(a_quarter.X_CL.size(), 4u);
  EXPECT_LT((a_quarter.X_CL[2].translation() - Eigen::Vector3d(std::cos(0.2), std::sin(0.2), 0)).norm(),
            1e-12);
  // The payload is the nearer sample's: none at a quarter, the carton at three quarters and at the sample.
  EXPECT_FALSE(a_quarter.state.payload.has_value());
  EXPECT_TRUE(buffer.at(1.006).state.payload.has_value());
  EXPECT_TRUE(buffer.at(1.008).state.payload.has_value());
  EXPECT_EQ(buffer.at(1.000).status, PoseLookup::kFound);
}

TEST(JointBufferTest, FramesWithoutBracketingSamplesArePendingOrMissing) {
  JointBuffer buffer(planar_arm(), 0.01);
  EXPECT_EQ(buffer.at(1.0).status, PoseLookup::kPending);  // nothing yet
  buffer.push({1.0, Eigen::Vector2d(0, 0), std::nullopt});
  buffer.push({1.05, Eigen::Vector2d(1, 1), std::nullopt});  // a 50 ms gap: more than the tolerance
  EXPECT_EQ(buffer.at(1.02).status, PoseLookup::kMissing);
  EXPECT_EQ(buffer.at(0.99).status, PoseLookup::kMissing);  // older than every sample
  EXPECT_EQ(buffer.at(1.06).status, PoseLookup::kPending);  // may still arrive
  EXPECT_EQ(buffer.at(NAN).status, PoseLookup::kMissing);
}

TEST(JointBufferTest, BadSamplesAreRefused) {
  JointBuffer buffer(planar_arm(), 0.01, 3);
  EXPECT_THROW(buffer.push({1.0, Eigen::Vector3d(0, 0, 0), std::nullopt}), Error);  // wrong size
  EXPECT_THROW(buffer.push({1.0, Eigen::Vector2d(0, NAN), std::nullopt}), Error);
  EXPECT_THROW(buffer.push({NAN, Eigen::Vector2d(0, 0), std::nullopt}), Error);
  Payload inverted;
  inverted.half_extents = Eigen::Vector3d(-1, 1, 1);
  EXPECT_THROW(buffer.push({1.0, Eigen::Vector2d(0, 0), inverted}), Error);
  for (int i = 0; i < 5; ++i) buffer.push({i * 0.001, Eigen::Vector2d(0, 0), std::nullopt});
  EXPECT_EQ(buffer.size(), 3u);  // the oldest dropped first
  EXPECT_EQ(buffer.at(0.001).status, PoseLookup::kMissing);
  EXPECT_THROW(JointBuffer(planar_arm(), 0.0), Error);
}

}  // namespace
}  // namespace cellmap
