// SPDX-License-Identifier: Apache-2.0
// Robot pose input: interpolation to frame times and the drop-without-pose rule.
#include "cellmap/frame/pose_buffer.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

#include "cellmap/common/error.hpp"
#include "cellmap/robot/robot.hpp"

namespace cellmap {
namespace {

Eigen::Isometry3d pose(double x, double y, double z, double yaw) {
  return Eigen::Translation3d(x, y, z) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
}

double max_difference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

TEST(InterpolatePoseTest, LinearPositionAndSlerpRotation) {
  const Eigen::Isometry3d a = pose(0, 0, 1, 0);
  const Eigen::Isometry3d b = pose(1, 2, 1, M_PI / 2);
  // A quarter of the way: position (0.25, 0.5, 1), yaw π/8 (slerp is uniform in angle).
  EXPECT_LT(max_difference(interpolate_pose(a, b, 0.25), pose(0.25, 0.5, 1, M_PI / 8)), 1e-12);
  EXPECT_LT(max_difference(interpolate_pose(a, b, 0.0), a), 1e-12);
  EXPECT_LT(max_difference(interpolate_pose(a, b, 1.0), b), 1e-12);
  // From yaw 170° to -170° the short way passes 180°, not 0°.
  const Eigen::Isometry3d mid =
      interpolate_pose(pose(0, 0, 0, 170 * M_PI / 180), pose(0, 0, 0, -170 * M_PI / 180), 0.5);
  EXPECT_LT(max_difference(mid, pose(0, 0, 0, M_PI)), 1e-12);
}

TEST(PoseBufferTest, InterpolatesBetweenBracketingSamples) {
  PoseBuffer buffer(0.05);
  buffer.push(10.00, pose(0, 0, 1, 0));
  buffer.push(10.04, pose(0.4, 0, 1, 0.4));
  const PoseBuffer::Result r = buffer.at(10.01);
  ASSERT_EQ(r.status, PoseLookup::kFound);
  EXPECT_LT(max_difference(r.X_CE, pose(0.1, 0, 1, 0.1)), 1e-9);
  // Exact sample times need only that sample.
  EXPECT_EQ(buffer.at(10.00).status, PoseLookup::kFound);
}

TEST(PoseBufferTest, SamplesMayArriveOutOfOrder) {
  PoseBuffer buffer(0.05);
  buffer.push(2.0, pose(2, 0, 0, 0));
  buffer.push(1.98, pose(1.98, 0, 0, 0));
  buffer.push(1.99, pose(5, 5, 5, 0));
  buffer.push(1.99, pose(1.99, 0, 0, 0));  // same stamp replaces
  EXPECT_EQ(buffer.size(), 3u);
  const PoseBuffer::Result r = buffer.at(1.995);
  ASSERT_EQ(r.status, PoseLookup::kFound);
  EXPECT_NEAR(r.X_CE.translation().x(), 1.995, 1e-12);
}

TEST(PoseBufferTest, NeverExtrapolatesNorBridgesGaps) {
  PoseBuffer buffer(0.05);
  EXPECT_EQ(buffer.at(1.0).status, PoseLookup::kPending);  // no pose yet
  buffer.push(1.0, pose(0, 0, 0, 0));
  buffer.push(1.2, pose(1, 0, 0, 0));  // the robot stream paused for 200 ms
  buffer.push(1.22, pose(1.1, 0, 0, 0));
  EXPECT_EQ(buffer.at(0.99).status, PoseLookup::kMissing);  // older than every sample
  EXPECT_EQ(buffer.at(1.1).status, PoseLookup::kMissing);   // inside the gap
  EXPECT_EQ(buffer.at(1.04).status, PoseLookup::kMissing);  // near 1.0 but 1.2 is too far
  EXPECT_EQ(buffer.at(1.21).status, PoseLookup::kFound);
  EXPECT_EQ(buffer.at(1.23).status, PoseLookup::kPending);  // newer than the newest: may still come
}

TEST(PoseBufferTest, DropsTheOldestBeyondCapacity) {
  PoseBuffer buffer(0.05, 3);
  for (int i = 0; i < 5; ++i) buffer.push(i * 0.01, pose(i, 0, 0, 0));
  EXPECT_EQ(buffer.size(), 3u);
  EXPECT_EQ(buffer.at(0.005).status, PoseLookup::kMissing);
  EXPECT_EQ(buffer.at(0.025).status, PoseLookup::kFound);
}

TEST(PoseBufferTest, RefusesBadSamples) {
  EXPECT_THROW(PoseBuffer(0.0), Error);
  PoseBuffer buffer(0.05);
  EXPECT_THROW(buffer.push(std::numeric_limits<double>::quiet_NaN(), pose(0, 0, 0, 0)), Error);
  Eigen::Isometry3d scaled = pose(0, 0, 0, 0);
  scaled.linear() *= 2.0;
  EXPECT_THROW(buffer.push(1.0, scaled), Error);
  Eigen::Isometry3d nan = pose(0, 0, 0, 0);
  nan.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(buffer.push(1.0, nan), Error);
  EXPECT_EQ(buffer.size(), 0u);
}

TEST(PoseBufferTest, JointVectorsGoThroughTheRobotsKinematics) {
  // A gantry whose tool looks down: X_CE(q) = Translation(q) * X_CE_zero.
  const Eigen::Isometry3d X_CE_zero(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  const Robot gantry = Robot::gantry(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 2, 1), X_CE_zero);
  PoseBuffer buffer(0.05);
  buffer.push_joints(5.00, gantry, Eigen::Vector3d(1.0, 0.5, 0.8));
  buffer.push_joints(5.02, gantry, Eigen::Vector3d(1.2, 0.5, 0.8));
  const PoseBuffer::Result r = buffer.at(5.01);
  ASSERT_EQ(r.status, PoseLookup::kFound);
  EXPECT_LT(max_difference(r.X_CE, Eigen::Translation3d(1.1, 0.5, 0.8) * X_CE_zero), 1e-12);
  EXPECT_THROW(buffer.push_joints(5.03, gantry, Eigen::Vector2d(1, 2)), Error);
}

TEST(PoseBufferTest, ReaderSeesConsistentPosesWhileAWriterPushes) {
  // The robot feeder and the sensor loop run on different threads: every pose a reader gets must lie on the
  // straight path being pushed (x = stamp, y = 2 stamp), never a torn or half-written sample.
  // The writer goes on until the reader has found 1000 poses while it was pushing: the reads and the writes
  // really overlap, however the two threads are scheduled.
  PoseBuffer buffer(0.02, 256);
  buffer.push(0.0, pose(0, 0, 0, 0));
  constexpr int kConcurrentReads = 1000;
  std::atomic<bool> done{false};
  std::atomic<int> newest{0};  // index of the newest pose pushed (stamp newest · 0.01 s)
  std::atomic<int> found_while_writing{0};
  std::thread writer([&] {
    for (int i = 1; i <= 20000 || (found_while_writing < kConcurrentReads && i < 50'000'000); ++i) {
      buffer.push(i * 0.01, pose(i * 0.01, i * 0.02, 0, 0));
      newest = i;
    }
    done = true;
  });
  while (!done) {
    const double latest = newest * 0.01;
    for (double t : {0.005, latest - 0.005, latest - 1.0, latest - 2.0}) {
      const PoseBuffer::Result r = buffer.at(t);
      if (r.status != PoseLookup::kFound) continue;
      ASSERT_NEAR(r.X_CE.translation().x(), t, 1e-9);
      ASSERT_NEAR(r.X_CE.translation().y(), 2 * t, 1e-9);
      ++found_while_writing;
    }
  }
  writer.join();
  EXPECT_GE(found_while_writing, kConcurrentReads);
  EXPECT_EQ(buffer.size(), 256u);
  EXPECT_EQ(buffer.at(newest * 0.01 - 0.005).status, PoseLookup::kFound);
  EXPECT_EQ(buffer.at(0.005).status, PoseLookup::kMissing);  // long dropped from the buffer
}

TEST(SensorPoserTest, ComposesTheHandEyeExtrinsicAndCountsDrops) {
  PoseBuffer buffer(0.05);
  buffer.push(1.00, pose(1, 0, 2, 0));
  buffer.push(1.04, pose(1, 0.4, 2, 0));
  buffer.push(2.00, pose(3, 0, 2, 0));  // a pause in the robot stream between 1.04 and 2.00
  const Eigen::Isometry3d X_ES = pose(0, 0.1, -0.05, M_PI / 2);
  SensorPoser poser(X_ES);

  Frame frame;
  frame.stamp = 1.02;
  ASSERT_EQ(poser.attach(frame, buffer), PoseLookup::kFound);
  EXPECT_LT(max_difference(frame.X_CS, pose(1, 0.2, 2, 0) * X_ES), 1e-12);
  // Sensor origin: tool at (1, 0.2, 2) plus the extrinsic's offset (0, 0.1, -0.05).
  EXPECT_LT((frame.X_CS.translation() - Eigen::Vector3d(1, 0.3, 1.95)).norm(), 1e-12);

  Frame in_gap;
  in_gap.stamp = 1.5;
  EXPECT_EQ(poser.attach(in_gap, buffer), PoseLookup::kMissing);
  EXPECT_TRUE(in_gap.X_CS.isApprox(Eigen::Isometry3d::Identity()));  // untouched: never a wrong pose
  Frame too_new;
  too_new.stamp = 2.5;
  EXPECT_EQ(poser.attach(too_new, buffer), PoseLookup::kPending);
  poser.give_up();
  EXPECT_EQ(poser.posed(), 1u);
  EXPECT_EQ(poser.dropped(), 2u);
}

}  // namespace
}  // namespace cellmap
