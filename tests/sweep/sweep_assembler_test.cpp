// SPDX-License-Identifier: Apache-2.0
// Frames → sweeps: posing by the robot's poses, the drop-without-pose rule, grouping by stamp.
#include "cellmap/sweep/sweep_assembler.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"
#include "support/test_support.hpp"

namespace cellmap {
namespace {

// One point 1 m in front of the sensor (z forward).
Frame frame_at(double stamp) {
  Frame frame;
  frame.sensor = "cam";
  frame.stamp = stamp;
  frame.points_S.push_back(pcl::PointXYZ(0, 0, 1));
  return frame;
}

Eigen::Isometry3d tool_at(double x) {
  Eigen::Isometry3d X_CE = Eigen::Isometry3d::Identity();
  X_CE.translation() = Eigen::Vector3d(x, 0, 0);
  return X_CE;
}

// Sensor 0.1 m above the tool along the tool's z, looking along the tool's x (a rotation about y).
Eigen::Isometry3d hand_eye() {
  Eigen::Isometry3d X_ES = Eigen::Isometry3d::Identity();
  X_ES.translation() = Eigen::Vector3d(0, 0, 0.1);
  X_ES.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return X_ES;
}

TEST(SweepAssemblerTest, SensorPoseIsToolPoseTimesHandEye) {
  PoseBuffer poses(0.06);
  poses.push(1.0, tool_at(0.0));
  poses.push(1.1, tool_at(1.0));
  SweepAssembler assembler({/*period=*/10.0, /*max_frames=*/1, /*pose_wait=*/0.5}, hand_eye());
  assembler.add(frame_at(1.05), 0.0);  // halfway: the tool is at x = 0.5
  const std::vector<Sweep> sweeps = assembler.poll(poses, 0.0);
  ASSERT_EQ(sweeps.size(), 1u);
  ASSERT_EQ(sweeps[0].scans.size(), 1u);
  const Scan& scan = sweeps[0].scans[0];
  EXPECT_TRUE(scan.origin_C.isApprox(Eigen::Vector3d(0.5, 0, 0.1), 1e-12));
  // The sensor's z axis is the tool's x axis: the point 1 m ahead lies at x = 1.5.
  EXPECT_TRUE(scan.points_C[0].getVector3fMap().isApprox(Eigen::Vector3f(1.5f, 0, 0.1f), 1e-6f));
  EXPECT_DOUBLE_EQ(sweeps[0].stamp, 1.05);
  EXPECT_EQ(assembler.posed(), 1u);
  EXPECT_EQ(assembler.dropped(), 0u);
}

TEST(SweepAssemblerTest, FramesWithoutAPoseWithinToleranceAreDroppedNeverFused) {
  PoseBuffer poses(0.05);
  poses.push(1.0, tool_at(0.0));
  poses.push(2.0, tool_at(1.0));  // a 1 s gap: nothing between is covered
  SweepAssembler assembler({10.0, 0, 0.5}, Eigen::Isometry3d::Identity());
  assembler.add(frame_at(0.5), 0.0);   // older than every pose
  assembler.add(frame_at(1.5), 0.0);   // inside the gap
  assembler.add(frame_at(1.02), 0.0);  // 0.02 s after a sample, but the next is 0.98 s away: no bridging
  assembler.add(frame_at(2.0), 0.0);   // exactly a sample
  EXPECT_TRUE(assembler.poll(poses, 0.0).empty());
  const std::vector<Sweep> sweeps = assembler.flush(poses);
  ASSERT_EQ(sweeps.size(), 1u);
  ASSERT_EQ(sweeps[0].scans.size(), 1u);  // only the frame at 2.0
  EXPECT_TRUE(sweeps[0].scans[0].origin_C.isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_EQ(assembler.posed(), 1u);
  EXPECT_EQ(assembler.dropped(), 3u);
}

TEST(SweepAssemblerTest, AFrameNewerThanEveryPoseWaitsThenIsDropped) {
  PoseBuffer poses(0.05);
  poses.push(1.0, tool_at(0.0));
  SweepAssembler assembler({10.0, 1, 0.5}, Eigen::Isometry3d::Identity());
  assembler.add(frame_at(1.02), 100.0);
  assembler.add(frame_at(1.04), 100.1);
  EXPECT_TRUE(assembler.poll(poses, 100.3).empty());
  EXPECT_EQ(assembler.waiting(), 2u);  // the controller may still send the pose
  poses.push(1.03, tool_at(0.3));      // arrives late: covers the first frame only
  std::vector<Sweep> sweeps = assembler.poll(poses, 100.4);
  ASSERT_EQ(sweeps.size(), 1u);
  EXPECT_NEAR(sweeps[0].scans[0].origin_C.x(), 0.2, 1e-12);
  EXPECT_EQ(assembler.waiting(), 1u);
  EXPECT_TRUE(assembler.poll(poses, 100.59).empty());  // waited 0.49 s
  EXPECT_TRUE(assembler.poll(poses, 100.61).empty());  // waited 0.51 s: given up
  EXPECT_EQ(assembler.waiting(), 0u);
  EXPECT_EQ(assembler.dropped(), 1u);
  EXPECT_EQ(assembler.posed(), 1u);
}

TEST(SweepAssemblerTest, GroupsFramesByStampPeriodAndFrameCount) {
  PoseBuffer poses(1.0);
  for (int i = 0; i <= 20; ++i) poses.push(i * 0.1, tool_at(i));
  SweepAssembler by_period({0.35, 0, 0.5}, Eigen::Isometry3d::Identity());
  for (int i = 0; i < 10; ++i) by_period.add(frame_at(i * 0.1), 0.0);
  std::vector<Sweep> sweeps = by_period.poll(poses, 0.0);
  // Frames 0–3 (0.0 … 0.3 < 0.35), 4–7, and 8–9 stays open until the stream ends.
  ASSERT_EQ(sweeps.size(), 2u);
  EXPECT_EQ(sweeps[0].scans.size(), 4u);
  EXPECT_EQ(sweeps[1].scans.size(), 4u);
  EXPECT_NEAR(sweeps[0].stamp, 0.3, 1e-12);
  EXPECT_NEAR(sweeps[1].scans[0].origin_C.x(), 4.0, 1e-12);
  sweeps = by_period.flush(poses);
  ASSERT_EQ(sweeps.size(), 1u);
  EXPECT_EQ(sweeps[0].scans.size(), 2u);
  EXPECT_TRUE(by_period.flush(poses).empty());

  SweepAssembler by_count({10.0, 3, 0.5}, Eigen::Isometry3d::Identity());
  for (int i = 0; i < 7; ++i) by_count.add(frame_at(i * 0.1), 0.0);
  sweeps = by_count.poll(poses, 0.0);
  ASSERT_EQ(sweeps.size(), 2u);
  EXPECT_EQ(sweeps[1].scans.size(), 3u);
  EXPECT_EQ(by_count.flush(poses).at(0).scans.size(), 1u);

  SweepAssembler each({0.0, 0, 0.5}, Eigen::Isometry3d::Identity());
  for (int i = 0; i < 3; ++i) each.add(frame_at(i * 0.1), 0.0);
  EXPECT_EQ(each.poll(poses, 0.0).size(), 2u);  // the third stays open
}

TEST(SweepAssemblerTest, RefusesBadSettings) {
  EXPECT_NE(test::error_of([] {
              SweepAssembler({-1.0, 0, 0.5}, Eigen::Isometry3d::Identity());
            }).find("period"),
            std::string::npos);
  EXPECT_NE(
      test::error_of([] {
        SweepAssembler({0.5, 0, std::numeric_limits<double>::quiet_NaN()}, Eigen::Isometry3d::Identity());
      }).find("pose_wait"),
      std::string::npos);
  Eigen::Isometry3d sheared = Eigen::Isometry3d::Identity();
  sheared.linear()(0, 1) = 0.5;
  EXPECT_NE(test::error_of([&] { SweepAssembler({0.5, 0, 0.5}, sheared); }).find("X_ES"), std::string::npos);
}

}  // namespace
}  // namespace cellmap
