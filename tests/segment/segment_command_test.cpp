// SPDX-License-Identifier: Apache-2.0
// `cellmap segment` as a process: exit codes, the one-line reason on bad input, and the boxes file it writes.
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include "cellmap/boxes/box.hpp"
#include "scenes.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;

struct ToolRun {
  int status = -1;
  std::string err;
};

// Runs the tool with `args`, capturing stderr.
ToolRun run_tool(const std::string& args) {
  const fs::path err_file =
      fs::temp_directory_path() / ("cellmap_segment_cli_" + std::to_string(::getpid()) + ".err");
  const std::string command =
      std::string(CELLMAP_TOOL) + " segment " + args + " 2> " + err_file.string() + " > /dev/null";
  ToolRun run;
  const int raw = std::system(command.c_str());
  run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(err_file);
  run.err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  fs::remove(err_file);
  return run;
}

// A 10 cm cube standing on a 40 cm floor square, seen from above one side.
test::Scene cube_on_floor() {
  test::Scene scene(Eigen::Vector3f(0.1f, -0.7f, 0.8f));
  scene.add_box({0.0, 0.0, 0.05}, {0.05, 0.05, 0.05}, Eigen::Matrix3d::Identity());
  scene.add_floor(0.2, {{Eigen::Vector2d(-0.05, -0.05), Eigen::Vector2d(0.05, 0.05)}});
  return scene;
}

class SegmentCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("cellmap_segment_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void expect_one_line_failure(const std::string& args, const std::string& names) {
    const ToolRun run = run_tool(args);
    EXPECT_NE(run.status, 0) << args;
    EXPECT_NE(run.status, -1) << args << " crashed";
    ASSERT_FALSE(run.err.empty());
    EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << "not one line: " << run.err;
    EXPECT_NE(run.err.find(names), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(dir_ / "out.json"));
  }
  fs::path dir_;
};

TEST_F(SegmentCommand, BadInputExitsNonZeroWithOneLineNamingTheFile) {
  const std::string out = " -o " + (dir_ / "out.json").string();
  std::ofstream(dir_ / "empty.pcd").close();
  expect_one_line_failure((dir_ / "empty.pcd").string() + out, "empty.pcd: is empty");
  std::ofstream(dir_ / "garbage.pcd") << "GIF89a this is not a cloud\n";
  expect_one_line_failure((dir_ / "garbage.pcd").string() + out, "garbage.pcd: not a PCD file");
  Cloud nan_cloud;
  for (int i = 0; i < 10; ++i) nan_cloud.push_back({NAN, NAN, NAN});
  pcl::io::savePCDFileBinary((dir_ / "nan.pcd").string(), nan_cloud);
  expect_one_line_failure((dir_ / "nan.pcd").string() + out, "nan.pcd: has no finite points");
  Cloud far;
  far.push_back({1e30f, 1.0f, 1.0f});
  pcl::io::savePCDFileBinary((dir_ / "far.pcd").string(), far);
  expect_one_line_failure((dir_ / "far.pcd").string() + out, "far.pcd: point 0 has an absurd coordinate");
  std::ofstream(dir_ / "bad.yaml") << "region_growing:\n  gap: 0\n";
  pcl::io::savePCDFileBinary((dir_ / "ok.pcd").string(), far);
  expect_one_line_failure(
      (dir_ / "ok.pcd").string() + " --pipeline points --config " + (dir_ / "bad.yaml").string() + out,
      "region_growing.gap");
  std::ofstream(dir_ / "bad_cell.yaml") << "segment:\n  region_growing:\n    gap: 0\n";
  expect_one_line_failure((dir_ / "ok.pcd").string() + " --config " + (dir_ / "bad_cell.yaml").string() + out,
                          "segment.region_growing.gap");
}

TEST_F(SegmentCommand, WritesTheBoxesFileOfAPlyScene) {
  const test::Scene scene = cube_on_floor();
  const fs::path ply = dir_ / "scene.ply";
  ASSERT_EQ(pcl::io::savePLYFileBinary(ply.string(), scene.points), 0);
  const fs::path out = dir_ / "boxes.json";
  // Without outlier removal every point is fitted to a box (the synthetic floor's rim would count as
  // outliers).
  std::ofstream(dir_ / "no_sor.yaml") << "outliers:\n  mode: 'off'\n";
  for (const std::string kind : {"obb", "aabb"}) {
    const ToolRun run = run_tool(ply.string() + " --pipeline points --boxes " + kind + " --config " +
                                 (dir_ / "no_sor.yaml").string() + " -o " + out.string());
    ASSERT_EQ(run.status, 0) << run.err;
    EXPECT_NE(run.err.find("boxes"), std::string::npos);
    EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << "summary is one line";
    const BoxSet set = read_box_file(out);
    EXPECT_EQ(set.version, 1u);
    ASSERT_GE(set.boxes.size(), 2u);
    std::uint64_t points = 0;
    for (std::size_t b = 0; b < set.boxes.size(); ++b) {
      EXPECT_EQ(set.boxes[b].id, b + 1);
      points += set.boxes[b].points;
      if (kind == "aabb") {
        EXPECT_TRUE(set.boxes[b].is_axis_aligned());
      }
    }
    EXPECT_EQ(points, scene.points.size());
    for (const auto& p : scene.points) {
      bool inside = false;
      for (const Box& box : set.boxes) inside |= box.contains(p.getVector3fMap().cast<double>(), 1e-9);
      EXPECT_TRUE(inside);
    }
  }
}

// The default path: the cloud as cellmapd's settled map. Boxes hold whole 2 cm voxels, so every point is
// inside one; `points` counts voxels.
TEST_F(SegmentCommand, CellPipelineBoxesHoldEveryPointOfAPlyScene) {
  const test::Scene scene = cube_on_floor();
  const fs::path ply = dir_ / "scene.ply";
  ASSERT_EQ(pcl::io::savePLYFileBinary(ply.string(), scene.points), 0);
  const fs::path out = dir_ / "boxes.json";
  const ToolRun run = run_tool(ply.string() + " -o " + out.string());
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.err.find("points outside every box 0"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << "summary is one line";
  const BoxSet set = read_box_file(out);
  ASSERT_GE(set.boxes.size(), 1u);
  EXPECT_LE(set.boxes.size(), 5u);  // the cube, the floor around it in up to 4 pieces (measured 4 in all)
  for (std::size_t b = 0; b < set.boxes.size(); ++b) EXPECT_EQ(set.boxes[b].id, b + 1);
  for (const auto& p : scene.points) {
    bool inside = false;
    for (const Box& box : set.boxes) inside |= box.contains(p.getVector3fMap().cast<double>(), 1e-6);
    EXPECT_TRUE(inside);
  }
}

}  // namespace
}  // namespace cellmap
