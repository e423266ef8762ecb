// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sweep/sweep.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace cellmap {
namespace {

Frame frame_at(const Eigen::Vector3d& p_CS, double yaw, double stamp) {
  Frame frame;
  frame.sensor = "cam";
  frame.stamp = stamp;
  frame.X_CS.translation() = p_CS;
  frame.X_CS.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  frame.points_S.push_back(pcl::PointXYZ(1, 0, 0));
  frame.points_S.push_back(pcl::PointXYZ(nan, nan, nan));  // an organized cloud's missing pixel
  frame.points_S.push_back(pcl::PointXYZ(0, 1, 2));
  return frame;
}

TEST(SweepTest, ToScanMovesPointsIntoTheCellAndKeepsTheOrigin) {
  const Scan scan = to_scan(frame_at({1, 2, 3}, M_PI / 2, 0.5));
  EXPECT_TRUE(scan.origin_C.isApprox(Eigen::Vector3d(1, 2, 3)));
  ASSERT_EQ(scan.points_C.size(), 2u);  // the NaN point is skipped
  // R_z(90°)·(1, 0, 0) = (0, 1, 0); R_z(90°)·(0, 1, 2) = (−1, 0, 2); then + (1, 2, 3).
  EXPECT_TRUE(scan.points_C[0].getVector3fMap().isApprox(Eigen::Vector3f(1, 3, 3), 1e-6f));
  EXPECT_TRUE(scan.points_C[1].getVector3fMap().isApprox(Eigen::Vector3f(0, 2, 5), 1e-6f));
}

// The frame's own points become the scan's: the same scan as to_scan, bit for bit, and the frame keeps
// everything but its points.
TEST(SweepTest, MoveToScanEqualsToScanAndEmptiesTheFramesPoints) {
  Frame frame = frame_at({1, 2, 3}, 0.3, 0.5);
  for (int i = 0; i < 1000; ++i) frame.points_S.push_back(pcl::PointXYZ(0.01f * i, 1.0f - 0.002f * i, 2.5f));
  const Scan copied = to_scan(frame);
  const pcl::PointXYZ* storage = frame.points_S.points.data();
  const Scan moved = move_to_scan(frame);
  EXPECT_EQ(moved.points_C.points.data(), storage);  // transformed where they lay
  EXPECT_EQ(moved.origin_C, copied.origin_C);
  ASSERT_EQ(moved.points_C.size(), copied.points_C.size());
  EXPECT_EQ(moved.points_C.width, copied.points_C.width);
  EXPECT_EQ(moved.points_C.height, 1u);
  EXPECT_TRUE(moved.points_C.is_dense);
  for (std::size_t i = 0; i < moved.points_C.size(); ++i) {
    EXPECT_EQ(moved.points_C[i].getVector3fMap(), copied.points_C[i].getVector3fMap()) << "point " << i;
  }
  EXPECT_TRUE(frame.points_S.empty());
  EXPECT_EQ(frame.points_S.width, 0u);
  EXPECT_EQ(frame.sensor, "cam");
  EXPECT_EQ(frame.stamp, 0.5);
}

TEST(SweepTest, MergeFramesKeepsOrderAndStampsTheLastFrame) {
  const Sweep sweep = merge_frames({frame_at({0, 0, 1}, 0, 1.0), frame_at({1, 0, 1}, 0, 1.2)});
  ASSERT_EQ(sweep.scans.size(), 2u);
  EXPECT_DOUBLE_EQ(sweep.stamp, 1.2);
  EXPECT_TRUE(sweep.scans[1].origin_C.isApprox(Eigen::Vector3d(1, 0, 1)));
  EXPECT_EQ(sweep.point_count(), 4u);
  EXPECT_EQ(sweep.merged().size(), 4u);
  EXPECT_EQ(merge_frames({}).stamp, 0.0);
}

}  // namespace
}  // namespace cellmap
