// SPDX-License-Identifier: Apache-2.0
// `cellmap simulate` as a user runs it: files on disk, exit codes, one-line errors.
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/sensor/depth_io.hpp"
#include "cellmap/sensor/replay_source.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/recording.hpp"
#include "cellmap/sim/simulator.hpp"

namespace cellmap::sim {
namespace {

namespace fs = std::filesystem;

struct ToolRun {
  int status;
  std::string err;
};

ToolRun run_tool(const std::string& args, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  const std::string command = std::string(CELLMAP_TOOL) + " " + args + " 2> " + err.string();
  const int raw = std::system(command.c_str());
  return ToolRun{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, fs::exists(err) ? read_file(err) : ""};
}

fs::path temp_dir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("cellmap_simulate_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::size_t pcd_points(const fs::path& file) {
  Cloud cloud;
  EXPECT_EQ(pcl::io::loadPCDFile(file.string(), cloud), 0) << file;
  return cloud.size();
}

TEST(SimulateCommandTest, LineScannerSweepWritesScansPosesAndTheMergedCloud) {
  const fs::path dir = temp_dir("os32c");
  const ToolRun run = run_tool("simulate --sensor os32c -o " + (dir / "out").string(), dir);
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.err.find("151 frames"), std::string::npos) << run.err;
  const std::vector<PoseRecord> poses = read_poses(dir / "out" / "frames.csv");
  ASSERT_EQ(poses.size(), 151u);
  std::size_t total = 0;
  for (const PoseRecord& pose : poses) total += pcd_points(dir / "out" / pose.file);
  EXPECT_GT(total, 10000u);
  EXPECT_EQ(pcd_points(dir / "out" / "merged.pcd"), total);
  // Equidistant stops 2 cm apart along x.
  EXPECT_NEAR((poses[1].X_CS.translation() - poses[0].X_CS.translation()).norm(), 0.02, 1e-12);
  fs::remove_all(dir);
}

TEST(SimulateCommandTest, ExactCameraSweepIsAReplayDirectoryOfTheSameFrames) {
  const fs::path dir = temp_dir("kinect");
  const ToolRun run =
      run_tool(std::string("simulate ") + CELLMAP_SOURCE_DIR +
                   "/config/cell.yaml --sensor kinect_v2 --exact --seed 9 -o " + (dir / "out").string(),
               dir);
  ASSERT_EQ(run.status, 0) << run.err;
  const Scene scene = default_scene();
  const int cam = scene.find_sensor("kinect_v2");
  const SensorSpec& spec = scene.sensors[static_cast<std::size_t>(cam)];
  const std::vector<SimFrame> expected = Simulator(scene, SimOptions{false, 2}).sweep(cam);
  const std::vector<PoseRecord> records = read_poses(dir / "out" / "frames.csv");
  ASSERT_EQ(records.size(), expected.size());

  // The sensor stage's replay source plays the directory back: the same depth images, the same tool poses.
  ReplayConfig config;
  config.directory = (dir / "out").string();
  config.playback = ReplayConfig::Playback::kFastest;
  ReplaySource replay(config);
  ASSERT_EQ(replay.open().state, SourceState::kConnected) << replay.status().reason;
  ASSERT_EQ(replay.size(), expected.size());
  const std::vector<StampedPose> tool_poses = replay.poses();
  std::size_t valid = 0;
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(records[k].q, scene.sweep.stops[k]);
    EXPECT_TRUE(records[k].X_CS.isApprox(expected[k].frame.X_CS, 1e-12));
    EXPECT_DOUBLE_EQ(tool_poses[k].stamp, expected[k].frame.stamp);
    EXPECT_TRUE((tool_poses[k].X_CE * spec.X_ES).isApprox(expected[k].frame.X_CS, 1e-12));
    const Frame played = replay.load(k);
    ASSERT_TRUE(played.depth.has_value());
    EXPECT_EQ(played.depth->depth, expected[k].frame.depth->depth);
    EXPECT_EQ(played.depth->intrinsics.fx, spec.intrinsics.fx);
    EXPECT_EQ(played.points_S.size(), expected[k].frame.points_S.size());
    valid += played.points_S.size();
  }
  EXPECT_EQ(pcd_points(dir / "out" / "merged.pcd"), valid);
  fs::remove_all(dir);
}

TEST(SimulateCommandTest, BadInputGivesOneLineReasonsAndNonZeroExit) {
  const fs::path dir = temp_dir("bad");
  std::string text = default_scene_yaml();
  const std::string from = "{name: floor, box:";
  text.replace(text.find(from), from.size(), "{name: floor, colour: grey, box:");
  write_file_atomically(dir / "typo.yaml", text);
  ToolRun run = run_tool("simulate " + (dir / "typo.yaml").string() + " -o " + (dir / "out").string(), dir);
  EXPECT_EQ(run.status, 1);
  EXPECT_EQ(run.err, "cellmap: " + (dir / "typo.yaml").string() + ": obstacles[0].colour: unknown key\n");
  run = run_tool("simulate --sensor kinect_v1 -o " + (dir / "out").string(), dir);
  EXPECT_EQ(run.status, 1);
  EXPECT_EQ(run.err.rfind("cellmap: simulate: --sensor kinect_v1: the scene has no such sensor", 0), 0u)
      << run.err;
  run = run_tool("simulate " + (dir / "missing.yaml").string() + " -o " + (dir / "out").string(), dir);
  EXPECT_EQ(run.status, 1);
  EXPECT_FALSE(fs::exists(dir / "out"));
  fs::remove_all(dir);
}

TEST(SimulateCommandTest, ArmCellWritesTheFramesOfItsFixedAndWristCameras) {
  const fs::path dir = temp_dir("arm");
  const std::string scene = std::string(CELLMAP_SOURCE_DIR) + "/config/scenes/arm_cell.yaml";
  for (const std::string sensor : {"post", "wrist"}) {
    const ToolRun run = run_tool("simulate " + scene + " --sensor " + sensor + " -o " + (dir / sensor).string(), dir);
    ASSERT_EQ(run.status, 0) << run.err;
    const std::vector<PoseRecord> poses = read_poses(dir / sensor / "frames.csv");
    ASSERT_EQ(poses.size(), 5u);
    EXPECT_EQ(poses[0].q.size(), 6);
    EXPECT_GT(pcd_points(dir / sensor / "merged.pcd"), 50000u);
    // The fixed camera stands still while the arm moves; the wrist camera moves with the arm.
    const double moved = (poses[4].X_CS.translation() - poses[0].X_CS.translation()).norm();
    if (sensor == "post") {
      EXPECT_EQ(moved, 0.0);
    } else {
      EXPECT_GT(moved, 1.0);
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cellmap::sim
