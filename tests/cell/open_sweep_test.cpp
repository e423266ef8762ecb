// SPDX-License-Identifier: Apache-2.0
// The open sweep: frames gathered one by one (on a thread of their own, as in cellmapd) make exactly what
// the whole sweep makes in the cell pipeline; a gathered frame keeps its pose, not its points; a frame that
// cannot be fused is left out.
#include "cellmap/cell/open_sweep.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <thread>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/simulator.hpp"

namespace cellmap {
namespace {

// cellmapd's shipped defaults, settled after 4 sweeps.
CellPipelineConfig defaults() {
  YamlMap root = YamlMap::load(CELLMAP_SOURCE_DIR "/config/cellmapd.yaml");
  CellPipelineConfig config = CellPipelineConfig::from_yaml(root);
  config.settle_sweeps = 4;
  return config;
}

// The default cell's Kinect binned 4× (128 × 106), with its noise: sweep `index`.
class KinectSweeps {
 public:
  KinectSweeps()
      : simulator_(coarse(), sim::SimOptions{true, 2}), sensor_(simulator_.scene().find_sensor("kinect")) {}
  [[nodiscard]] FrameSweep sweep(std::uint64_t index) const {
    FrameSweep sweep;
    for (sim::SimFrame& f : simulator_.sweep(sensor_, index)) {
      sweep.stamp = std::max(sweep.stamp, f.frame.stamp);
      sweep.frames.push_back(SweepFrame{std::move(f.frame), std::nullopt, 0.0});
    }
    return sweep;
  }
  // The cell with a crate added on the table from then on.
  void add_crate() {
    (void)simulator_.apply(transport::SceneEdit::add_box("crate", {2.12, 0.45, 0.9}, {0.1, 0.1, 0.15}));
  }

 private:
  static sim::Scene coarse() {
    sim::Scene scene = sim::default_scene();
    sim::SensorSpec& kinect = scene.sensors[scene.find_sensor("kinect")];
    kinect.intrinsics.width = 128;
    kinect.intrinsics.height = 106;
    kinect.intrinsics.fx = kinect.intrinsics.fy = 91.25;
    kinect.intrinsics.cx = 63.5;
    kinect.intrinsics.cy = 52.5;
    scene.validate();
    return scene;
  }
  sim::Simulator simulator_;
  int sensor_;
};

TEST(OpenSweepTest, FramesGatheredOnAnotherThreadMakeWhatTheWholeSweepMakes) {
  KinectSweeps cell;
  CellPipeline whole(defaults()), gathered(defaults());
  OpenSweep open = gathered.open_sweep();
  int versions = 0;
  for (std::uint64_t index = 0; index < 14; ++index) {
    if (index == 6) cell.add_crate();
    FrameSweep frames = cell.sweep(index);
    FrameSweep copy = frames;
    const SweepReport expected = whole.process(std::move(frames));
    std::thread gatherer([&] {
      for (SweepFrame& frame : copy.frames) open.add(std::move(frame));
    });
    gatherer.join();
    GatheredSweep sweep = open.close();
    EXPECT_EQ(open.frames(), 0u);
    const SweepReport report = gathered.process(sweep);
    EXPECT_EQ(report.frames, expected.frames);
    EXPECT_EQ(report.points, expected.points);
    EXPECT_EQ(report.hit_voxels, expected.hit_voxels);
    EXPECT_EQ(report.free_voxels, expected.free_voxels);
    EXPECT_EQ(report.flipped, expected.flipped);
    ASSERT_EQ(report.change.has_value(), expected.change.has_value()) << "sweep " << index;
    versions += report.change ? 1 : 0;
  }
  EXPECT_GE(versions, 2) << "the settled cell, then the crate";
  const auto holds_crate = [](const Box& box) { return box.contains(Eigen::Vector3d(2.12, 0.45, 1.04)); };
  EXPECT_TRUE(std::any_of(gathered.boxes().begin(), gathered.boxes().end(), holds_crate));
  ASSERT_EQ(gathered.boxes().size(), whole.boxes().size());
  for (std::size_t b = 0; b < whole.boxes().size(); ++b) {
    EXPECT_EQ(gathered.boxes()[b].id, whole.boxes()[b].id);
    EXPECT_EQ(gathered.boxes()[b].center, whole.boxes()[b].center);
    EXPECT_EQ(gathered.boxes()[b].half_extents, whole.boxes()[b].half_extents);
  }
  EXPECT_TRUE(gathered.map_state() == whole.map_state())
      << "the maps (log-odds, viewpoint, pending flips) differ";
}

// Frames waiting together are gathered side by side: the same map as one by one, no-return rays included
// (their pixel phases go frame by frame as before), and a frame that fails is left out alone.
TEST(OpenSweepTest, FramesGatheredSideBySideMakeWhatOneByOneMakes) {
  const KinectSweeps cell;
  CellPipeline one_by_one(defaults()), side_by_side(defaults());
  OpenSweep single = one_by_one.open_sweep(), batched = side_by_side.open_sweep();
  for (std::uint64_t index = 0; index < 3; ++index) {
    FrameSweep frames = cell.sweep(index);
    ASSERT_GE(frames.frames.size(), 3u);
    for (SweepFrame& frame : frames.frames) frame.no_return_range = 2.0;
    SweepFrame broken = frames.frames.back();
    broken.frame.sensor = "broken";
    broken.frame.X_CS.translation() = Eigen::Vector3d(1e6, 0.0, 0.0);
    frames.frames.insert(frames.frames.begin() + 1, broken);
    std::vector<SweepFrame> batch = frames.frames;
    for (SweepFrame& frame : frames.frames) {
      if (frame.frame.sensor == "broken") {
        EXPECT_THROW(single.add(std::move(frame)), Error);
      } else {
        single.add(std::move(frame));
      }
    }
    const std::vector<std::string> faults = batched.add(std::move(batch));
    ASSERT_EQ(faults.size(), 1u);
    EXPECT_EQ(faults[0].rfind("frame of 'broken' at ", 0), 0u) << faults[0];
    EXPECT_EQ(batched.frames(), single.frames());
    GatheredSweep a = single.close(), b = batched.close();
    EXPECT_EQ(b.no_return_rays, a.no_return_rays);
    EXPECT_GT(b.no_return_rays, 0u);
    EXPECT_GT(b.t_gathering, 0.0);
    (void)one_by_one.process(a);
    (void)side_by_side.process(b);
  }
  EXPECT_TRUE(side_by_side.map_state() == one_by_one.map_state());
}

TEST(OpenSweepTest, AGatheredFrameKeepsItsPoseAndStampNotItsPoints) {
  const KinectSweeps cell;
  FrameSweep frames = cell.sweep(0);
  ASSERT_GT(frames.frames.size(), 1u);
  std::size_t points = 0;
  for (const SweepFrame& f : frames.frames) points += to_scan(f.frame).points_C.size();
  const FrameSweep original = frames;
  OpenSweep open(OccupancyConfig{});
  for (SweepFrame& frame : frames.frames) open.add(std::move(frame));
  EXPECT_EQ(open.frames(), original.frames.size());
  const GatheredSweep sweep = open.close();
  EXPECT_EQ(sweep.points, points);
  EXPECT_EQ(sweep.voxels.scans(), original.frames.size());
  EXPECT_EQ(sweep.frames.stamp, original.stamp);
  ASSERT_EQ(sweep.frames.frames.size(), original.frames.size());
  Eigen::Vector3d origin_sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < original.frames.size(); ++i) {
    const Frame& kept = sweep.frames.frames[i].frame;
    const Frame& taken = original.frames[i].frame;
    EXPECT_EQ(kept.sensor, taken.sensor);
    EXPECT_EQ(kept.stamp, taken.stamp);
    EXPECT_TRUE(kept.X_CS.isApprox(taken.X_CS, 0.0));
    EXPECT_TRUE(kept.points_S.empty());
    ASSERT_TRUE(kept.depth.has_value());
    EXPECT_TRUE(kept.depth->depth.empty()) << "the depth pixels are gone with the points";
    EXPECT_EQ(kept.depth->intrinsics.width, taken.depth->intrinsics.width) << "the field of view stays";
    origin_sum += taken.X_CS.translation();
  }
  EXPECT_TRUE(sweep.viewpoint_C.isApprox(origin_sum / double(original.frames.size()), 1e-12));
  EXPECT_GT(sweep.t_gather, 0.0);
}

TEST(OpenSweepTest, AFrameThatCannotBeFusedIsLeftOut) {
  const KinectSweeps cell;
  FrameSweep frames = cell.sweep(0);
  OpenSweep open(OccupancyConfig{});
  open.add(std::move(frames.frames[0]));
  SweepFrame far = frames.frames[1];
  far.frame.X_CS.translation() = Eigen::Vector3d(1e6, 0.0, 0.0);  // beyond the map's key range
  EXPECT_THROW(open.add(std::move(far)), Error);
  EXPECT_EQ(open.frames(), 1u);
  const GatheredSweep sweep = open.close();
  EXPECT_EQ(sweep.voxels.scans(), 1u);
  EXPECT_EQ(sweep.frames.frames.size(), 1u);
}

}  // namespace
}  // namespace cellmap
