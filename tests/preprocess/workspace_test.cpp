// SPDX-License-Identifier: Apache-2.0
#include "cellmap/preprocess/workspace.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"
#include "cellmap/robot/robot.hpp"
#include "cellmap/urdf/urdf_model.hpp"

#include <cmath>

namespace cellmap {
namespace {

TEST(Workspace, BoxCropsToItsRange) {
  const Workspace w = Workspace::box({0, 0, 0}, {1, 2, 3});
  Cloud cloud;
  cloud.push_back({0.5f, 1.0f, 1.0f});   // in
  cloud.push_back({1.5f, 1.0f, 1.0f});   // out in x
  cloud.push_back({0.0f, 2.0f, 3.0f});   // on the corner: in
  cloud.push_back({0.5f, -0.1f, 1.0f});  // out in y
  EXPECT_EQ(crop_to_workspace(cloud, w), (std::vector<int>{0, 2}));
  EXPECT_THROW((void)Workspace::box({1, 0, 0}, {0, 1, 1}), Error);
}

TEST(Workspace, VoxelSetCoversEverythingWithinTheEnvelope) {
  // Samples along a line (like a tool path); the envelope is 0.1 m.
  std::vector<Eigen::Vector3d> samples;
  for (int i = 0; i <= 10; ++i) samples.emplace_back(0.1 * i, 0.0, 0.5);
  const Workspace w = Workspace::from_points(samples, 0.1, 0.05);
  EXPECT_FALSE(w.is_box());
  EXPECT_GT(w.voxel_count(), 0u);
  // Every point within the envelope of a sample is inside.
  for (double x = -0.09; x <= 1.09; x += 0.01) {
    for (double dy : {-0.099, 0.0, 0.07}) EXPECT_TRUE(w.contains({x, dy, 0.5})) << x << " " << dy;
  }
  EXPECT_TRUE(w.contains({0.5, 0.0, 0.599}));
  // Far away points are outside (the voxels reach at most envelope + one voxel diagonal).
  EXPECT_FALSE(w.contains({0.5, 0.3, 0.5}));
  EXPECT_FALSE(w.contains({1.4, 0.0, 0.5}));
  EXPECT_FALSE(w.contains({0.5, 0.0, 0.0}));
  EXPECT_THROW((void)Workspace::from_points({}, 0.1, 0.05), Error);
  EXPECT_THROW((void)Workspace::from_points(samples, 0.1, 0.0), Error);
}

TEST(Workspace, GantryReachIsItsAxisBoxGrownByTheEnvelope) {
  // The tool hangs 0.3 m below the ram's origin; axes x in [0, 2], y in [-1, 1], z in [0.5, 1.5].
  const Eigen::Isometry3d X_CE_zero(Eigen::Translation3d(0.0, 0.0, -0.3));
  const Robot gantry = Robot::gantry({0.0, -1.0, 0.5}, {2.0, 1.0, 1.5}, X_CE_zero);
  const Workspace w = workspace_from_robot(gantry, 0.25, 10, 0.05);
  ASSERT_TRUE(w.is_box());
  EXPECT_TRUE(w.bounds().min.isApprox(Eigen::Vector3d(-0.25, -1.25, -0.05), 1e-12));
  EXPECT_TRUE(w.bounds().max.isApprox(Eigen::Vector3d(2.25, 1.25, 1.45), 1e-12));
}

TEST(Workspace, ArmReachIsSampledAndVoxelised) {
  // A planar two-link arm (0.6 m + 0.5 m) turning about z: it reaches the ring 0.1 m <= r <= 1.1 m for the
  // elbow range used here, at z = 0.
  const std::string urdf = R"(<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/><link name="upper"/><link name="fore"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3.14159" upper="3.14159" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.6 0 0"/><axis xyz="0 0 1"/><limit lower="0" upper="1.0" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="fore"/><child link="tip"/><origin xyz="0.5 0 0"/></joint>
  <link name="tip"/>
</robot>)";
  const Robot arm = UrdfModel::parse(urdf).chain("tip");
  const Workspace w = workspace_from_robot(arm, 0.1, 60, 0.05);
  EXPECT_FALSE(w.is_box());
  // At elbow 0 the tip is 1.1 m out; at elbow 1 rad |tip| = |0.6 + 0.5 e^{i}| = 0.963 m.
  for (double angle = 0.0; angle < 6.28; angle += 0.3) {
    EXPECT_TRUE(w.contains({1.1 * std::cos(angle), 1.1 * std::sin(angle), 0.0})) << angle;
    EXPECT_TRUE(w.contains({1.0 * std::cos(angle), 1.0 * std::sin(angle), 0.05})) << angle;
  }
  EXPECT_FALSE(w.contains({0.0, 0.0, 0.0}));  // the base: the tool never gets there
  EXPECT_FALSE(w.contains({1.5, 0.0, 0.0}));  // beyond reach + envelope + voxel
  EXPECT_FALSE(w.contains({1.0, 0.0, 0.5}));  // above the plane of motion
  EXPECT_THROW((void)workspace_from_robot(arm, 0.1, 1, 0.05), Error);
}

}  // namespace
}  // namespace cellmap
