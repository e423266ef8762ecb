// SPDX-License-Identifier: Apache-2.0
// The cell pipeline on depth frames built by hand (an 80 × 60 camera at the cell's origin looking along +z):
// pixels without a return clearing their line of sight (SweepFrame::no_return_range), and a change confirmed
// in two parts a sweep apart published as one version (change.gather_sweeps). Known answers, milliseconds.
#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <vector>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/config/yaml_map.hpp"

namespace cellmap {
namespace {

constexpr int kWidth = 80, kHeight = 60;

PinholeIntrinsics camera() {
  PinholeIntrinsics in;
  in.width = kWidth;
  in.height = kHeight;
  in.fx = in.fy = 160.0;  // 1.25 cm pixels at 2 m, 1.9 cm at 3 m: every 2 cm voxel of a surface gets a point
  in.cx = 39.5;
  in.cy = 29.5;
  in.min_range = 0.1;
  in.max_range = 5.0;
  return in;
}

// Depth in metres along z per pixel (0 = no return).
using Scene = std::function<double(int u, int v)>;

SweepFrame frame_of(const Scene& scene, double no_return_range) {
  DepthImage image;
  image.intrinsics = camera();
  image.depth.assign(static_cast<std::size_t>(kWidth * kHeight), 0);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u)
      image.depth[static_cast<std::size_t>(v * kWidth + u)] =
          static_cast<std::uint16_t>(scene(u, v) * 1000.0);
  }
  SweepFrame f;
  f.frame.sensor = "camera";
  f.frame.points_S = depth_to_points(image);
  f.frame.depth = std::move(image);
  f.no_return_range = no_return_range;
  return f;
}

// Four frames: the no-return rays of four frames use every pixel once.
FrameSweep sweep_of(const Scene& scene, double no_return_range = 0.0) {
  FrameSweep sweep;
  for (int i = 0; i < 4; ++i) sweep.frames.push_back(frame_of(scene, no_return_range));
  return sweep;
}

// cellmapd's shipped defaults, settled after 3 sweeps, axis-aligned boxes.
CellPipelineConfig config() {
  YamlMap root = YamlMap::load(CELLMAP_SOURCE_DIR "/config/cellmapd.yaml");
  CellPipelineConfig c = CellPipelineConfig::from_yaml(root);
  c.settle_sweeps = 3;
  c.segment.box_kind = BoxKind::kAxisAligned;
  return c;
}

// A wall 3 m away filling the image, and in front of it, 2 m away, a panel over the pixels of `panel`.
Scene wall_and_panel(const std::function<bool(int u, int v)>& panel) {
  return [panel](int u, int v) { return panel(u, v) ? 2.0 : 3.0; };
}

const Eigen::Vector3d kPanelCentre(0.0, 0.0, 2.01);  // the pixels around the optical axis at 2 m

// 16 cm × 16 cm at 2 m.
bool panel_centre(int u, int v) {
  return u >= 27 && u < 53 && v >= 17 && v < 43;
}

std::size_t boxes_holding(const CellPipeline& pipeline, const Eigen::Vector3d& p_C) {
  std::size_t n = 0;
  for (const Box& b : pipeline.boxes()) n += b.contains(p_C) ? 1 : 0;
  return n;
}

// The panel alone (nothing behind it within range): boxed; then gone, every pixel without a return.
// Returns the sweep after which the panel's box went (nullopt: still there after 30 sweeps).
std::optional<int> panel_removed_after(double no_return_range, std::size_t& rays_per_sweep) {
  CellPipeline pipeline(config());
  const Scene panel = [](int u, int v) { return panel_centre(u, v) ? 2.0 : 0.0; };
  for (int i = 0; i < 6; ++i) (void)pipeline.process(sweep_of(panel, no_return_range));
  EXPECT_EQ(boxes_holding(pipeline, kPanelCentre), 1u) << "the panel was not boxed";
  const Scene nothing = [](int, int) { return 0.0; };
  for (int i = 1; i <= 30; ++i) {
    const SweepReport report = pipeline.process(sweep_of(nothing, no_return_range));
    rays_per_sweep = report.no_return_rays;
    if (boxes_holding(pipeline, kPanelCentre) == 0) return i;
  }
  return std::nullopt;
}

TEST(CellPipelineFramesTest, PixelsWithoutAReturnClearTheirLineOfSightOnlyWhenTheSourceSaysSo) {
  std::size_t rays = 0;
  EXPECT_EQ(panel_removed_after(0.0, rays), std::nullopt) << "no return cleared with no_return_range 0";
  EXPECT_EQ(rays, 0u);
  // Cleared like any removal seen through: sweeps_to_clear() + persist_sweeps - 1 = 11 sweeps.
  const std::optional<int> removed = panel_removed_after(4.0, rays);
  ASSERT_TRUE(removed.has_value()) << "the panel's box stayed with no_return_range 4";
  // Six sweeps of hits put it at the upper clamp; cleared like any removal seen through.
  EXPECT_EQ(*removed, config().occupancy.sweeps_to_clear() + config().change.persist_sweeps - 1);
  EXPECT_EQ(rays, static_cast<std::size_t>(kWidth * kHeight));  // a quarter of the pixels in each frame
}

TEST(CellPipelineFramesTest, NoReturnRaysEndAtTheirRangeAndFramesWithoutAnImageAddNone) {
  CellPipeline pipeline(config());
  const Scene nothing = [](int, int) { return 0.0; };
  (void)pipeline.process(sweep_of(nothing, 1.0));
  // Free up to 1 m along the optical axis, unknown beyond.
  EXPECT_EQ(pipeline.map().state(Eigen::Vector3d(0.01, 0.01, 0.95)), VoxelState::free);
  EXPECT_EQ(pipeline.map().state(Eigen::Vector3d(0.01, 0.01, 1.05)), VoxelState::unknown);
  FrameSweep scanner = sweep_of(nothing, 1.0);
  for (SweepFrame& f : scanner.frames) f.frame.depth.reset();
  EXPECT_EQ(pipeline.process(scanner).no_return_rays, 0u);
}

// A line scanner's beams that saw nothing within range (Frame::no_return_S, at its range_max) clear up to
// no_return_range or their end, whichever is nearer; with no_return_range 0, nothing.
TEST(CellPipelineFramesTest, ScannerBeamsWithoutAReturnClearUpToTheNearerOfTheirEndAndTheRange) {
  const auto scan = [](double no_return_range) {
    SweepFrame f;
    f.frame.sensor = "lidar";
    f.frame.X_CS.translation() = Eigen::Vector3d(0.01, 0.01, 0.01);
    f.frame.no_return_S.push_back(pcl::PointXYZ(2.0f, 0.0f, 0.0f));  // range_max 2 m along +x
    f.frame.no_return_S.push_back(pcl::PointXYZ(0.0f, 4.0f, 0.0f));  // range_max 4 m along +y
    f.no_return_range = no_return_range;
    FrameSweep sweep;
    sweep.frames.push_back(std::move(f));
    return sweep;
  };
  CellPipeline off(config());
  EXPECT_EQ(off.process(scan(0.0)).no_return_rays, 0u);
  CellPipeline pipeline(config());
  EXPECT_EQ(pipeline.process(scan(3.0)).no_return_rays, 2u);
  EXPECT_EQ(pipeline.map().state(Eigen::Vector3d(1.9, 0.01, 0.01)), VoxelState::free);
  EXPECT_EQ(pipeline.map().state(Eigen::Vector3d(2.1, 0.01, 0.01)), VoxelState::unknown);  // its own end
  EXPECT_EQ(pipeline.map().state(Eigen::Vector3d(0.01, 2.9, 0.01)), VoxelState::free);
  EXPECT_EQ(pipeline.map().state(Eigen::Vector3d(0.01, 3.1, 0.01)), VoxelState::unknown);  // no_return_range
}

// A panel appears in two halves three sweeps apart (the left half confirmed when the right one gets its first
// hit): with gather_sweeps 0 each half is a version (the right half touches the left, whose voxels are new,
// so it is a change of its own); with 3, one version holds both.
std::vector<std::vector<Box>> versions_of_a_panel_in_two_halves(int gather_sweeps,
                                                                bool gather_removals = true) {
  CellPipelineConfig c = config();
  c.gather_sweeps = gather_sweeps;
  c.gather_removals = gather_removals;
  CellPipeline pipeline(c);
  const Scene wall = wall_and_panel([](int, int) { return false; });
  const Scene left = wall_and_panel([](int u, int v) { return panel_centre(u, v) && u < 40; });
  const Scene whole = wall_and_panel(panel_centre);
  std::vector<std::vector<Box>> versions;
  const auto run = [&](const Scene& scene, int sweeps) {
    for (int i = 0; i < sweeps; ++i) {
      if (pipeline.process(sweep_of(scene)).change) versions.push_back(pipeline.boxes());
    }
  };
  run(wall, 6);
  run(left, 3);
  run(whole, 12);
  return versions;
}

TEST(CellPipelineFramesTest, GatherSweepsPublishesAChangeConfirmedInTwoPartsAsOneVersion) {
  const std::vector<std::vector<Box>> apart = versions_of_a_panel_in_two_halves(0);
  const std::vector<std::vector<Box>> gathered = versions_of_a_panel_in_two_halves(3);
  ASSERT_EQ(gathered.size(), 2u) << "the wall, then the whole panel";
  EXPECT_EQ(apart.size(), 3u) << "the wall, the panel's left half, its right half";
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(-0.1, 0.0, 2.01), Eigen::Vector3d(0.1, 0.0, 2.01)}) {
    std::size_t held = 0;
    for (const Box& b : gathered.back()) held += b.contains(p) ? 1 : 0;
    EXPECT_GE(held, 1u) << "the gathered version leaves out the panel at " << p.transpose();
  }
}

// The sweep, counted from the panel's going, whose version takes it away: the panel stood whole for 12
// sweeps in front of the wall.
int version_after_the_panel_goes(int gather_sweeps, bool gather_removals) {
  CellPipelineConfig c = config();
  c.gather_sweeps = gather_sweeps;
  c.gather_removals = gather_removals;
  CellPipeline pipeline(c);
  const Scene wall = wall_and_panel([](int, int) { return false; });
  const Scene panel = wall_and_panel(panel_centre);
  for (int i = 0; i < 6; ++i) (void)pipeline.process(sweep_of(wall));
  for (int i = 0; i < 12; ++i) (void)pipeline.process(sweep_of(panel));
  for (int sweep = 1; sweep <= 40; ++sweep) {
    if (pipeline.process(sweep_of(wall)).change) return sweep;
  }
  return -1;
}

TEST(CellPipelineFramesTest, GatherRemovalsFalsePublishesARemovalAtOnceAndStillGathersAnArrival) {
  const int at_once = version_after_the_panel_goes(0, true);
  ASSERT_GT(at_once, 0) << "the panel's going made no version";
  EXPECT_EQ(version_after_the_panel_goes(3, true), at_once + 3);
  EXPECT_EQ(version_after_the_panel_goes(3, false), at_once);
  EXPECT_EQ(versions_of_a_panel_in_two_halves(3, false).size(), 2u) << "the wall, then the whole panel";
}

TEST(CellPipelineFramesTest, GatherSweepsOutOfRangeIsRefused) {
  CellPipelineConfig c = config();
  c.gather_sweeps = -1;
  EXPECT_THROW(CellPipeline{c}, Error);
  c.gather_sweeps = 1001;
  EXPECT_THROW(CellPipeline{c}, Error);
}

}  // namespace
}  // namespace cellmap
