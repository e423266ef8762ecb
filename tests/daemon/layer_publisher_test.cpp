// SPDX-License-Identifier: Apache-2.0
// The daemon's layers: written after a sweep only while read, only when they changed or a reader joined
// (real participants on loopback, one domain per test); sensor views from real frames through the sweep
// stage.
#include "layer_publisher.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <optional>
#include <thread>

#include "cellmap/sweep/sweep.hpp"
#include "support/dds_domains.hpp"
#include "support/test_support.hpp"
#include "transport/loopback.hpp"

namespace cellmap::daemon {
namespace {

using namespace std::chrono_literals;
using test::kPatience;
using transport::Layer;

class LayerPublisherTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::use_loopback(); }
};

// A sweep seen from 1 m above with one point at the centre of each voxel (i, j, 0), i < nx, j < ny, of the
// 2 cm grid: one hit makes a voxel occupied with the default sensor model.
Sweep floor_sweep(int nx, int ny) {
  Scan scan;
  scan.origin_C = {0.05, 0.03, 1.0};
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) scan.points_C.push_back({0.01f + 0.02f * i, 0.01f + 0.02f * j, 0.01f});
  Sweep sweep;
  sweep.scans.push_back(scan);
  return sweep;
}

template <class Layer>
Layer next_layer(transport::LayerReader& reader) {
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (std::chrono::steady_clock::now() < deadline) {
    for (transport::LayerMessage& message : reader.take(100ms)) return std::get<Layer>(std::move(message));
  }
  ADD_FAILURE() << "no layer within " << kPatience.count() << " s";
  return {};
}

void wait_until_read(const dds::Participant& participant, Layer layer, std::uint32_t readers) {
  const transport::LayerWriter probe(participant, "probe");  // sees the same readers as the daemon's
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (probe.readers(layer) < readers && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(5ms);
  ASSERT_GE(probe.readers(layer), readers);
}

TEST_F(LayerPublisherTest, VoxelsGoOutWhenTheyChangeOrAReaderJoins) {
  dds::Participant daemon(test::domain::kVoxelLayerPublisher);
  dds::Participant viewer(test::domain::kVoxelLayerPublisher);
  LayerPublisher layers(daemon, "cell-1");
  OccupancyMap map;
  map.integrate(floor_sweep(5, 3));
  layers.after_sweep(1, {}, map, {});  // nobody reads: nothing is computed or written

  transport::LayerReader reader(viewer, Layer::kVoxels);
  wait_until_read(daemon, Layer::kVoxels, 1);
  layers.after_sweep(2, {}, map, {});
  const auto first = next_layer<transport::VoxelLayer>(reader);
  EXPECT_EQ(first.cell, "cell-1");
  EXPECT_EQ(first.sweep, 2u);
  EXPECT_EQ(first.resolution, 0.02);
  const std::vector<transport::VoxelRun> rows{{0, 0, 0, 5}, {0, 1, 0, 5}, {0, 2, 0, 5}};
  EXPECT_EQ(first.runs, rows);

  layers.after_sweep(3, {}, map, {});  // unchanged and nobody new: not written
  map.integrate(floor_sweep(6, 3));
  layers.after_sweep(4, {}, map, {});
  const auto second = next_layer<transport::VoxelLayer>(reader);
  EXPECT_EQ(second.sweep, 4u);  // not 3
  EXPECT_EQ(second.voxel_count(), 18u);

  transport::LayerReader newcomer(viewer, Layer::kVoxels);
  wait_until_read(daemon, Layer::kVoxels, 2);
  layers.after_sweep(5, {}, map, {});  // unchanged, but the newcomer has nothing yet
  EXPECT_EQ(next_layer<transport::VoxelLayer>(newcomer).sweep, 5u);
  EXPECT_EQ(next_layer<transport::VoxelLayer>(reader).sweep, 5u);
}

TEST_F(LayerPublisherTest, ChangeRegionsGoOutForSweepsThatConfirmedSome) {
  dds::Participant daemon(test::domain::kRegionLayerPublisher);
  dds::Participant viewer(test::domain::kRegionLayerPublisher);
  LayerPublisher layers(daemon, "cell-1");
  OccupancyMap map;
  transport::LayerReader reader(viewer, Layer::kChangeRegions);
  wait_until_read(daemon, Layer::kChangeRegions, 1);

  layers.after_sweep(1, {}, map, {});  // the reader just joined: it learns there is nothing yet
  EXPECT_TRUE(next_layer<transport::ChangeRegionLayer>(reader).regions.empty());
  layers.after_sweep(2, {}, map, {});  // nothing confirmed: not written
  ChangeSet changes;
  ChangeRegion region;
  region.bounds = {{0.1, 0.2, 0.3}, {0.4, 0.5, 0.6}};
  region.appeared.resize(7);
  region.vanished.resize(2);
  changes.regions.push_back(region);
  layers.after_sweep(3, {}, map, changes);
  const auto got = next_layer<transport::ChangeRegionLayer>(reader);
  EXPECT_EQ(got.sweep, 3u);
  ASSERT_EQ(got.regions.size(), 1u);
  EXPECT_EQ(got.regions[0].bounds.min, region.bounds.min);
  EXPECT_EQ(got.regions[0].bounds.max, region.bounds.max);
  EXPECT_EQ(got.regions[0].appeared, 7u);
  EXPECT_EQ(got.regions[0].vanished, 2u);
}

// A camera frame (a 4 × 2 depth image, 1 m everywhere) and a line scanner's frame at two poses.
std::vector<Frame> camera_and_scanner_frames() {
  Frame camera;
  camera.sensor = "kinect";
  camera.X_CS = Eigen::Translation3d(1.0, 2.0, 2.4) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
  camera.depth = DepthImage{{4, 2, 2.0, 2.0, 1.5, 0.5, 0.001, 0.5, 4.5}, std::vector<std::uint16_t>(8, 1000)};
  camera.points_S = depth_to_points(*camera.depth);
  Frame scanner;
  scanner.sensor = "os32c";
  scanner.X_CS = Eigen::Translation3d(0.5, 0.0, 1.0) * Eigen::Isometry3d::Identity();
  scanner.field_of_view = FieldOfView{{{1, 0, 0}, {0, 1, 0}}, false, 10.0};
  return {camera, scanner};
}

TEST_F(LayerPublisherTest, SensorViewsGoOutAfterEachSweepWhileRead) {
  dds::Participant daemon(test::domain::kSensorLayerPublisher);
  dds::Participant viewer(test::domain::kSensorLayerPublisher);
  LayerPublisher layers(daemon, "cell-1");
  const OccupancyMap map;
  FrameSweep sweep;
  for (Frame& frame : camera_and_scanner_frames()) sweep.frames.push_back({std::move(frame), std::nullopt});
  layers.after_sweep(1, sweep, map, {});  // nobody reads: not written

  transport::LayerReader reader(viewer, Layer::kSensors);
  wait_until_read(daemon, Layer::kSensors, 1);
  layers.after_sweep(2, sweep, map, {});
  const auto got = next_layer<transport::SensorLayer>(reader);
  EXPECT_EQ(got.sweep, 2u);
  ASSERT_EQ(got.views.size(), 2u);
  EXPECT_EQ(got.views[0].sensor, "kinect");
  EXPECT_TRUE(got.views[0].X_CS.isApprox(sweep.frames[0].frame.X_CS, 1e-12));
  ASSERT_TRUE(got.views[0].field_of_view);
  const FieldOfView& frustum = *got.views[0].field_of_view;
  EXPECT_TRUE(frustum.closed);
  EXPECT_EQ(frustum.max_range, 4.5);
  ASSERT_EQ(frustum.outline_S.size(), 4u);
  // The image's top left edge, (-0.5, -0.5) in pixels, is at x = (-0.5 - 1.5) / 2, y = (-0.5 - 0.5) / 2.
  EXPECT_TRUE(frustum.outline_S[0].isApprox(Eigen::Vector3d(-1.0, -0.5, 1.0).normalized(), 1e-12));
  EXPECT_TRUE(frustum.outline_S[2].isApprox(Eigen::Vector3d(1.0, 0.5, 1.0).normalized(), 1e-12));
  EXPECT_EQ(got.views[1].sensor, "os32c");
  ASSERT_TRUE(got.views[1].field_of_view);
  EXPECT_FALSE(got.views[1].field_of_view->closed);
  EXPECT_EQ(got.views[1].field_of_view->outline_S, sweep.frames[1].frame.field_of_view->outline_S);

  layers.after_sweep(3, sweep, map, {});  // the sensors move with every sweep: written each time
  EXPECT_EQ(next_layer<transport::SensorLayer>(reader).sweep, 3u);
}

// The robot layer shows the robot at the sweep's last frame that posed it: the gantry's parts are boxes given
// at q = 0 in the cell frame, so at q each lies moved by the axes that carry it.
TEST_F(LayerPublisherTest, RobotShapesFollowTheJointsOfEachSweep) {
  dds::Participant daemon(test::domain::kRobotLayerPublisher);
  dds::Participant viewer(test::domain::kRobotLayerPublisher);
  const Eigen::Vector3d lower(0, 0, -0.6), upper(3, 2, 0);
  const Eigen::Isometry3d X_CE_zero =
      Eigen::Translation3d(0, 0, 2.4) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
  const GantryParts parts = GantryParts::fitting(lower, upper, X_CE_zero);
  const Robot robot = Robot::gantry(lower, upper, X_CE_zero, parts);
  LayerPublisher layers(daemon, "cell-1");
  SelfFilterConfig filter;
  filter.padding = 0.03;
  layers.show_robot(robot, filter);
  const OccupancyMap map;
  const auto sweep_at = [&](const Eigen::Vector3d& q, std::optional<Payload> payload) {
    FrameSweep sweep;
    sweep.frames.push_back(
        {Frame{}, RobotAt{robot.link_poses(Eigen::Vector3d(0.5, 1.0, 0.0)), std::nullopt}});
    sweep.frames.push_back({Frame{}, RobotAt{robot.link_poses(q), std::move(payload)}});
    sweep.frames.push_back({Frame{}, std::nullopt});  // a frame without the robot's pose: not the latest
    return sweep;
  };
  transport::LayerReader reader(viewer, Layer::kRobot);
  wait_until_read(daemon, Layer::kRobot, 1);

  const Eigen::Vector3d q1(2.5, 1.0, -0.2);
  layers.after_sweep(1, sweep_at(q1, std::nullopt), map, {});
  const auto first = next_layer<transport::RobotLayer>(reader);
  EXPECT_EQ(first.sweep, 1u);
  EXPECT_EQ(first.padding_scale, 1.0);
  EXPECT_EQ(first.padding, 0.03);
  ASSERT_EQ(first.shapes.size(), 3u);
  const std::pair<const char*, Eigen::Vector3d> expected[] = {
      {"bridge", parts.bridge.center + Eigen::Vector3d(q1.x(), 0, 0)},
      {"carriage", parts.carriage.center + Eigen::Vector3d(q1.x(), q1.y(), 0)},
      {"ram", parts.ram.center + q1}};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(first.shapes[i].link, expected[i].first);
    EXPECT_FALSE(first.shapes[i].carried);
    EXPECT_TRUE(first.shapes[i].X_CG.translation().isApprox(expected[i].second, 1e-12))
        << expected[i].first << " at " << first.shapes[i].X_CG.translation().transpose();
    EXPECT_TRUE(first.shapes[i].X_CG.linear().isIdentity(1e-12));
  }
  EXPECT_EQ(std::get<BoxShape>(first.shapes[2].geometry).half_extents, parts.ram.half_extents);

  // The joints changed, and the tool holds a carton 0.2 m below the flange (the tool's z points down).
  const Eigen::Vector3d q2(0.4, 1.5, -0.5);
  Payload carton{Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.2)), {0.15, 0.1, 0.1}};
  layers.after_sweep(2, sweep_at(q2, carton), map, {});
  const auto second = next_layer<transport::RobotLayer>(reader);
  EXPECT_EQ(second.sweep, 2u);
  ASSERT_EQ(second.shapes.size(), 4u);
  EXPECT_TRUE(second.shapes[2].X_CG.translation().isApprox(parts.ram.center + q2, 1e-12));
  const transport::PosedShape& held = second.shapes[3];
  EXPECT_TRUE(held.carried);
  EXPECT_EQ(held.link, "ram");
  EXPECT_TRUE(held.X_CG.translation().isApprox(Eigen::Vector3d(0.4, 1.5, 2.4 - 0.5 - 0.2), 1e-12));
  EXPECT_EQ(std::get<BoxShape>(held.geometry).half_extents, carton.half_extents);
}

TEST_F(LayerPublisherTest, NoRobotLayerWithoutARobotModel) {
  dds::Participant daemon(test::domain::kNoRobotLayerPublisher);
  dds::Participant viewer(test::domain::kNoRobotLayerPublisher);
  const Robot robot = Robot::gantry({0, 0, -0.6}, {3, 2, 0});
  LayerPublisher layers(daemon, "cell-2");  // show_robot() never called
  transport::LayerReader reader(viewer, Layer::kRobot);
  wait_until_read(daemon, Layer::kRobot, 1);
  FrameSweep sweep;
  sweep.frames.push_back({Frame{}, RobotAt{robot.link_poses(Eigen::Vector3d(1, 1, 0)), std::nullopt}});
  layers.after_sweep(1, sweep, OccupancyMap{}, {});
  layers.show_robot(robot, SelfFilterConfig{});
  layers.after_sweep(2, sweep, OccupancyMap{}, {});
  const auto got = next_layer<transport::RobotLayer>(reader);
  EXPECT_EQ(got.sweep, 2u);         // not 1
  EXPECT_TRUE(got.shapes.empty());  // a kinematics-only gantry has no shapes
}

}  // namespace
}  // namespace cellmap::daemon
