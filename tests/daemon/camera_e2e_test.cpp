// SPDX-License-Identifier: Apache-2.0
// cellmapd with real camera sources, as a real process on loopback DDS:
// - a replay of the three real grabber frames (../shared/data) produces a persisted and published
//   environment whose boxes hold the frames' points, in the cell frame given by the recorded tool pose;
// - the real OpenNI2 driver path (Debian's Dummy device) with robot poses over cellmap/robot_state: frames
//   without a pose are dropped and counted, frames with one are fused;
// - OpenNI2 with no device: the daemon keeps running, reports degraded/disconnected, stops on SIGTERM.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <thread>

#include "cellmap/common/wall_clock.hpp"
#include "cellmap/environment/version_store.hpp"
#include "cellmap/sensor/depth_io.hpp"
#include "cellmap/sensor/replay_source.hpp"
#include "cellmap/transport/environment_subscriber.hpp"
#include "cellmap/transport/robot_joints.hpp"
#include "cellmap/transport/robot_state.hpp"
#include "cellmap/transport/status_reader.hpp"
#include "daemon/service_e2e.hpp"
#include "support/dds_domains.hpp"
#include "support/shared_data.hpp"
#include "support/test_support.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// Debian's OpenNI2 Dummy device at 320x240 (see below).
const char* kDummy =
    "{uri: Dummy, width: 320, height: 240, intrinsics: {fx: 285, fy: 285, cx: 159.5, cy: 119.5}}";

// The tool 1.5 m above the floor at (1, 2), the camera looking along the cell's +x: camera x (right) = cell
// -y, camera y (down) = cell -z, camera z (forward) = cell +x.
const char* kToolPose = "1.0,2.0,1.5,0.5,-0.5,0.5,-0.5";

class CameraE2eTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::use_loopback(); }

  std::unique_ptr<test::ChildProcess> start_daemon(const std::string& yaml, int domain,
                                                   std::uint64_t sweeps = 0) {
    const fs::path config = dir_.path() / "cellmapd.yaml";
    std::ofstream(config) << yaml;
    std::vector<std::string> argv{
        CELLMAPD,      "--config",          config.string(), "--domain", std::to_string(domain),
        "--state-dir", state_dir().string()};
    if (sweeps > 0) {
      argv.push_back("--sweeps");
      argv.push_back(std::to_string(sweeps));
    }
    return std::make_unique<test::ChildProcess>(argv);
  }

  fs::path state_dir() const { return dir_.path() / "state"; }

  test::TempDir dir_{"cellmap-camera-e2e"};
};

TEST_F(CameraE2eTest, ReplayOfTheGrabberFramesProducesAnEnvironmentHoldingTheirPoints) {
  const fs::path data = test::shared_data_dir() / "pcl" / "grabber_sequence";
  CELLMAP_SKIP_WITHOUT_DATA(data);
  std::vector<fs::path> frames;
  for (const auto& entry : fs::directory_iterator(data)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 11 && name.compare(name.size() - 11, 11, "_depth.tiff") == 0)
      frames.push_back(entry.path());
  }
  std::sort(frames.begin(), frames.end());
  ASSERT_EQ(frames.size(), 3u);
  // The three frames six times, 1 s apart: a static camera watching for 18 s. An empty map publishes its
  // first version once it has settled (change.settle_sweeps = 15 in config/cellmapd.yaml), so at sweep 15.
  constexpr int kSweeps = 18;
  const fs::path replay = dir_.path() / "replay";
  fs::create_directories(replay);
  {
    std::ofstream poses(replay / "poses.csv");
    poses << "file,stamp,x,y,z,qw,qx,qy,qz\n";
    for (int i = 0; i < kSweeps; ++i)
      poses << frames[i % 3].string() << "," << 100 + i << "," << kToolPose << "\n";
  }
  const std::string yaml =
      "cell: replay\nsweep_period: 0\nstatus_period: 0.2\nsource:\n  kind: replay\n"
      "  sensor: grabber\n  replay: {directory: replay, playback: fastest}\n";

  const dds::Participant participant(test::domain::kReplay);
  transport::EnvironmentSubscriber planner(participant, "replay");
  transport::StatusReader reader(participant);
  auto daemon = start_daemon(yaml, test::domain::kReplay, kSweeps);
  EXPECT_TRUE(planner.wait_for_version(1, test::kDaemonPatience)) << "no version published from the replay";
  const auto stopped = test::wait_for_status(
      reader, "replay", [](const transport::CellStatus& s) { return s.state == "stopped"; });
  const int status = daemon->wait();
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
      << "cellmapd --sweeps " << kSweeps << " did not exit cleanly";

  // The persisted environment, as a restarted daemon would resume it.
  const Environment env = VersionStore(state_dir(), "replay").recovered().environment;
  ASSERT_GE(env.version(), 1u);
  ASSERT_GT(env.boxes().size(), 0u);
  ASSERT_TRUE(planner.environment().has_value());
  EXPECT_LE(planner.environment()->version(), env.version());
  // The last report: stopped, every sweep processed and none dropped (`playback: fastest` waits for the
  // processing thread), the version and boxes that went out.
  ASSERT_TRUE(stopped.has_value()) << "no final stopped status";
  EXPECT_EQ(stopped->sweeps, static_cast<std::uint64_t>(kSweeps));
  EXPECT_EQ(stopped->dropped_frames, 0u);
  EXPECT_EQ(stopped->version, env.version());
  EXPECT_EQ(stopped->boxes, env.boxes().size());

  // Every box lies in front of the camera (cell +x from x = 1) and below it: the recorded tool pose was
  // applied. An ignored pose would put the scene around the cell's z axis instead.
  for (const Box& box : env.boxes()) {
    EXPECT_GT(box.center.x(), 1.0) << "box " << box.id;
    EXPECT_LT(box.center.z(), 1.5 + 1.0) << "box " << box.id;
  }
  // The frames' points within the map's range (5 m from the sensor) are inside the boxes.
  ReplayConfig config;
  config.directory = replay.string();
  ReplaySource source(config);
  ASSERT_EQ(source.open().state, SourceState::kConnected) << source.status().reason;
  std::size_t in_range = 0, covered = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    const Frame frame = source.load(i);
    const Eigen::Isometry3d X_CS = source.poses()[i].X_CE;  // identity hand-eye extrinsic
    for (const pcl::PointXYZ& p : frame.points_S) {
      if (p.getVector3fMap().norm() > 5.0f) continue;
      ++in_range;
      const Eigen::Vector3d p_C = X_CS * p.getVector3fMap().cast<double>();
      for (const Box& box : env.boxes()) {
        if (box.contains(p_C)) {
          ++covered;
          break;
        }
      }
    }
  }
  const double fraction = static_cast<double>(covered) / static_cast<double>(in_range);
  std::cout << "replay: version " << env.version() << ", " << env.boxes().size() << " boxes, " << covered
            << " of " << in_range << " points in range inside a box (" << fraction << ")\n";
  EXPECT_GT(in_range, 600000u);
  // Measured: 813 873 of 814 298 (99.95 %); the rest fell into voxels hit only once (flying pixels).
  EXPECT_GE(fraction, 0.99);
}

// A replay that ends, or whose last frame cannot be read, degrades the cell (`ended`, `error`); the version
// made before stays published, for late joiners too. The parameter: a bad frame at the end.
class DegradedReplayTest : public CameraE2eTest, public ::testing::WithParamInterface<bool> {};

TEST_P(DegradedReplayTest, KeepsTheLastVersionPublished) {
  const bool bad_frame = GetParam();
  const int domain = bad_frame ? test::domain::kReplayError : test::domain::kReplayEnded;
  // Four frames of a 160 × 120 camera (kToolPose) facing a wall 2 m ahead with a block 0.5 m in front of it.
  const fs::path replay = dir_.path() / "replay";
  fs::create_directories(replay);
  RawDepth image{160, 120, std::vector<std::uint16_t>(160 * 120, 2000)};
  for (int v = 40; v < 80; ++v)
    for (int u = 50; u < 110; ++u) image.depth[static_cast<std::size_t>(v * 160 + u)] = 1500;
  write_depth_png((replay / "wall.png").string(), image);
  std::ofstream(replay / "intrinsics.yaml")
      << "width: 160\nheight: 120\nfx: 150\nfy: 150\ncx: 79.5\ncy: 59.5\ndepth_scale: 0.001\n";
  std::ofstream(replay / "bad.png") << "not a PNG";
  {
    std::ofstream poses(replay / "poses.csv");
    poses << "file,stamp,x,y,z,qw,qx,qy,qz\n";
    for (int i = 0; i < 4; ++i) poses << "wall.png," << 100 + i << "," << kToolPose << "\n";
    if (bad_frame) poses << "bad.png,104," << kToolPose << "\n";
  }
  const std::string yaml =
      "cell: degraded\nsweep_period: 0\nstatus_period: 0.2\nchange: {settle_sweeps: 2}\nsource:\n"
      "  kind: replay\n  sensor: post\n  replay: {directory: replay, playback: fastest}\n";
  const dds::Participant participant(domain);
  transport::StatusReader reader(participant);
  auto daemon = start_daemon(yaml, domain);
  const std::string expected_state = bad_frame ? "error" : "ended";
  const auto degraded = test::wait_for_status(reader, "degraded", [&](const transport::CellStatus& s) {
    return s.state == "degraded" && s.version >= 1 && s.sensors.size() == 1 &&
           s.sensors[0].state.rfind(expected_state, 0) == 0;
  });
  ASSERT_TRUE(degraded.has_value()) << "no degraded/" << expected_state << " status after a version";
  EXPECT_NE(degraded->reason.find(bad_frame ? "bad.png" : "end of recording"), std::string::npos)
      << degraded->reason;
  EXPECT_GT(degraded->boxes, 0u);
  EXPECT_EQ(degraded->dropped_frames, 0u);

  // A late joiner gets that version, with the boxes the status counts.
  transport::EnvironmentSubscriber late(participant, "degraded");
  ASSERT_TRUE(late.wait_for_version(degraded->version, test::kDaemonPatience)) << "the last version is gone";
  EXPECT_EQ(late.environment()->version(), degraded->version);
  EXPECT_EQ(late.environment()->boxes().size(), degraded->boxes);
  EXPECT_TRUE(daemon->running());
  daemon->signal(SIGTERM);
  EXPECT_EQ(test::exit_code(daemon->wait()), 0);
}

INSTANTIATE_TEST_SUITE_P(, DegradedReplayTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? "BadFrame" : "End";
                         });

TEST_F(CameraE2eTest, OpenNI2WithoutADeviceKeepsRunningDegradedAndStopsOnSigterm) {
  const std::string yaml =
      "cell: no-device\nstatus_period: 0.2\nsource:\n  kind: openni2\n  sensor: wrist\n"
      "  openni2: {reconnect: {initial_backoff: 0.2, max_backoff: 0.5}}\n";
  const dds::Participant participant(test::domain::kNoDevice);
  transport::StatusReader reader(participant);
  auto daemon = start_daemon(yaml, test::domain::kNoDevice);
  const auto degraded = test::wait_for_status(reader, "no-device", [](const transport::CellStatus& s) {
    return s.state == "degraded" && s.sensors.size() == 1 && s.sensors[0].state.rfind("disconnected", 0) == 0;
  });
  ASSERT_TRUE(degraded.has_value()) << "no degraded/disconnected status";
  EXPECT_EQ(degraded->sensors[0].name, "wrist");
  EXPECT_NE(degraded->sensors[0].state.find("no devices found"), std::string::npos)
      << degraded->sensors[0].state;
  EXPECT_EQ(degraded->version, 0u);
  EXPECT_EQ(degraded->sweeps, 0u);
  // Still running and reporting, five reports later: retrying with back-off, not exiting.
  int reports = 0;
  const auto later = test::wait_for_status(reader, "no-device", [&](const transport::CellStatus& s) {
    return s.state == "degraded" && ++reports >= 5;
  });
  ASSERT_TRUE(later.has_value()) << "the daemon stopped reporting";
  EXPECT_TRUE(daemon->running()) << "cellmapd exited without a device";
  daemon->signal(SIGTERM);
  const int status = daemon->wait();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "wait status " << status;
}

// The real OpenNI2 driver path: Debian's Dummy device streams 320x240 depth at 30 fps (row 0 at 2 m, a disc
// near 1 m). Poses come over cellmap/robot_state from this test, as a robot controller would send them.
TEST_F(CameraE2eTest, FramesArePosedFromTheRobotStateTopicAndDroppedWithoutIt) {
  const std::string yaml =
      "cell: wrist-cell\nsweep_period: 0.5\nstatus_period: 0.2\nsource:\n  kind: openni2\n  sensor: wrist\n"
      "  pose_tolerance: 0.05\n  pose_wait: 0.3\n"
      "  openni2: {uri: Dummy, width: 320, height: 240, intrinsics: {fx: 285, fy: 285, cx: 159.5, cy: "
      "119.5}}\n";
  const dds::Participant participant(test::domain::kRobotPose);
  transport::StatusReader reader(participant);
  auto daemon = start_daemon(yaml, test::domain::kRobotPose);

  // No robot poses yet: frames stream but are dropped, none is fused.
  const auto unposed = test::wait_for_status(
      reader, "wrist-cell", [](const transport::CellStatus& s) { return s.dropped_frames >= 10; });
  ASSERT_TRUE(unposed.has_value()) << "frames without a pose were not counted as dropped";
  EXPECT_EQ(unposed->sweeps, 0u) << "a frame without a pose was fused";
  ASSERT_EQ(unposed->sensors.size(), 1u);
  EXPECT_EQ(unposed->sensors[0].state, "streaming");

  // A robot controller at 100 Hz: the tool at rest, stamped on the same clock as the frames.
  transport::RobotStateWriter writer(participant, "wrist-cell");
  std::atomic<bool> stop{false};
  std::thread controller([&] {
    transport::RobotState state;
    state.cell = "wrist-cell";
    state.X_CE.translation() = Eigen::Vector3d(1.0, 2.0, 1.5);
    while (!stop) {
      state.stamp_ns = wall_clock_ns();
      writer.write(state);
      std::this_thread::sleep_for(10ms);
    }
  });
  const auto posed = test::wait_for_status(reader, "wrist-cell",
                                           [](const transport::CellStatus& s) { return s.sweeps >= 3; });
  stop = true;
  controller.join();
  ASSERT_TRUE(posed.has_value()) << "no sweep was fused with poses from cellmap/robot_state";
  EXPECT_EQ(posed->state, "running");
  EXPECT_EQ(posed->sensors[0].state, "streaming");

  daemon->signal(SIGTERM);
  const int status = daemon->wait();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "wait status " << status;
}

// Two cameras, one of them unplugged: the cell is degraded and names it, the other keeps mapping.
TEST_F(CameraE2eTest, OneOfTwoCamerasUnpluggedDegradesTheCellAndTheOtherKeepsTheMapCurrent) {
  const std::string yaml =
      std::string(
          "cell: two-cameras\nsweep_period: 0.5\nstatus_period: 0.2\n"
          "change: {settle_sweeps: 2}\nsources:\n"
          "  - {kind: openni2, sensor: post, mount: cell, pose: {position: [1, 2, 1.5]}, "
          "openni2: ") +
      kDummy +
      "}\n"
      "  - {kind: v4l2, sensor: wrist, v4l2: {device: /dev/cellmap-unplugged, "
      "reconnect: {initial_backoff: 0.2, max_backoff: 0.5}}}\n";
  const dds::Participant participant(test::domain::kUnplugged);
  transport::StatusReader reader(participant);
  transport::EnvironmentSubscriber planner(participant, "two-cameras");
  auto daemon = start_daemon(yaml, test::domain::kUnplugged);

  const auto degraded = test::wait_for_status(reader, "two-cameras", [](const transport::CellStatus& s) {
    return s.state == "degraded" && s.sweeps >= 4;
  });
  ASSERT_TRUE(degraded.has_value()) << "no degraded status with sweeps from the camera still streaming";
  EXPECT_EQ(degraded->reason.rfind("sensor 'wrist': disconnected", 0), 0u) << degraded->reason;
  ASSERT_EQ(degraded->sensors.size(), 2u);
  EXPECT_EQ(degraded->sensors[0].name, "post");
  EXPECT_EQ(degraded->sensors[0].state, "streaming");
  EXPECT_EQ(degraded->sensors[1].name, "wrist");
  EXPECT_EQ(degraded->sensors[1].state.rfind("disconnected", 0), 0u) << degraded->sensors[1].state;
  EXPECT_TRUE(planner.wait_for_version(1, test::kDaemonPatience))
      << "the streaming camera's map was not published";

  daemon->signal(SIGTERM);
  const int status = daemon->wait();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "wait status " << status;
}

// A camera on the gantry's tool posed from cellmap/robot_joints through the daemon's robot model.
TEST_F(CameraE2eTest, FramesArePosedFromJointSamplesThroughTheRobotModel) {
  const std::string yaml = std::string(
                               "cell: joints-cell\nsweep_period: 0.5\nstatus_period: 0.2\n"
                               "robot: {gantry: {lower: [0, 0, 0], upper: [3, 2, 1]}}\n"
                               "source: {kind: openni2, sensor: wrist, openni2: ") +
                           kDummy + "}\n";
  const dds::Participant participant(test::domain::kJointsCamera);
  transport::StatusReader reader(participant);
  auto daemon = start_daemon(yaml, test::domain::kJointsCamera);
  const auto unposed = test::wait_for_status(
      reader, "joints-cell", [](const transport::CellStatus& s) { return s.dropped_frames >= 10; });
  ASSERT_TRUE(unposed.has_value()) << "frames without joint samples were not counted as dropped";
  EXPECT_EQ(unposed->sweeps, 0u) << "a frame without joint samples was fused";

  // The controller at 100 Hz, the gantry at rest mid-cell, stamped on the frames' clock.
  transport::RobotJointsWriter writer(participant, "joints-cell");
  std::atomic<bool> stop{false};
  std::thread controller([&] {
    transport::RobotJoints joints;
    joints.cell = "joints-cell";
    joints.names = {"x", "y", "z"};
    joints.positions = {1.5, 1.0, 0.8};
    while (!stop) {
      joints.stamp_ns = wall_clock_ns();
      writer.write(joints);
      std::this_thread::sleep_for(10ms);
    }
  });
  const auto posed = test::wait_for_status(reader, "joints-cell",
                                           [](const transport::CellStatus& s) { return s.sweeps >= 3; });
  stop = true;
  controller.join();
  ASSERT_TRUE(posed.has_value()) << "no sweep was fused with poses from cellmap/robot_joints";
  EXPECT_EQ(posed->state, "running");
  EXPECT_EQ(posed->refused_inputs, 0u);

  daemon->signal(SIGTERM);
  const int status = daemon->wait();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "wait status " << status;
}

}  // namespace
}  // namespace cellmap
