// SPDX-License-Identifier: Apache-2.0
// cellmapd's acquisition of the simulated cell: sweeps into the frame queue, scene edits over real DDS
// applied when they are for this cell (or every cell), ignored when they are for another, refused and counted
// when they leave the cell.
#include "acquisition.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cellmap/transport/scene_edits.hpp"
#include "support/dds_domains.hpp"
#include "transport/loopback.hpp"

namespace cellmap::daemon {
namespace {

using namespace std::chrono_literals;

// Points of `sweep` inside the axis-aligned box at `centre` with `half_extents` grown by 5 mm, leaving out
// the 5 cm above the table it stands on.
std::size_t points_above_table(const FrameSweep& sweep, const Eigen::Vector3d& centre,
                               const Eigen::Vector3d& half_extents) {
  std::size_t inside = 0;
  for (const SweepFrame& frame : sweep.frames) {
    for (const pcl::PointXYZ& p : to_scan(frame.frame).points_C) {
      const Eigen::Vector3d d = p.getVector3fMap().cast<double>() - centre;
      const bool above_table = d.z() > 0.05 - half_extents.z();
      if (above_table && (d.cwiseAbs().array() <= half_extents.array() + 0.005).all()) ++inside;
    }
  }
  return inside;
}

// The sweeps in `frames`: the frames up to each end of a sweep.
std::vector<FrameSweep> take_sweeps(FrameQueue& frames) {
  std::vector<FrameSweep> sweeps(1);
  while (std::optional<FrameItem> item = frames.take(0ms)) {
    if (item->frame) {
      sweeps.back().frames.push_back(std::move(*item->frame));
    } else {
      sweeps.emplace_back();
    }
  }
  if (sweeps.back().frames.empty()) sweeps.pop_back();
  return sweeps;
}

transport::SceneEdit add_box(const std::string& cell, const std::string& name,
                             const Eigen::Vector3d& centre) {
  transport::SceneEdit edit;
  edit.cell = cell;
  edit.kind = transport::SceneEdit::Kind::kAddBox;
  edit.name = name;
  edit.center = centre;
  edit.half_extents = Eigen::Vector3d(0.1, 0.1, 0.15);
  return edit;
}

TEST(SimAcquisitionTest, DeliversSweepsAndAppliesOnlyThisCellsSceneEdits) {
  test::use_loopback();
  DaemonConfig config =
      DaemonConfig::parse("cell: bench-7\nsweep_period: 0\nsource: {noise: false}\n", "test.yaml", ".");
  const dds::Participant participant(test::domain::kSimAcquisition);
  FrameQueue frames(1000);
  Health health(config.cell, {config.sources[0].sensor});
  std::vector<std::string> refusal_lines;
  InputRefusals refusals([&](const std::string& line) { refusal_lines.push_back(line); });
  const std::atomic<std::uint64_t> version{0};
  const std::unique_ptr<Acquisition> acquisition =
      make_acquisition(config, participant, {frames, health, refusals, version});
  EXPECT_EQ(acquisition->describe().rfind("sim (sensor 'kinect', ", 0), 0u) << acquisition->describe();

  // Two free spots on the table (top at z = 0.75), both in the Kinect's view.
  const Eigen::Vector3d mine(2.12, 0.45, 0.9), theirs(0.5, 1.5, 0.9), half(0.1, 0.1, 0.15);
  const transport::SceneEditWriter writer(participant, "bench-7");
  const transport::SceneEditWriter other_cell(participant, "bench-8");
  ASSERT_TRUE(writer.wait_for_reader(30s));
  EXPECT_FALSE(other_cell.wait_for_reader(0s)) << "the daemon reads another cell's partition";
  writer.write(add_box("bench-7", "mine", mine));
  other_cell.write(add_box("bench-8", "theirs", theirs));
  writer.write(add_box("bench-7", "far", Eigen::Vector3d(1e300, 0.45, 0.9)));
  ASSERT_TRUE(writer.wait_for_acks(30s));

  const std::atomic<bool> stop{false};
  acquisition->run(stop, 2);  // returns after two sweeps
  const std::vector<FrameSweep> sweeps = take_sweeps(frames);
  ASSERT_EQ(sweeps.size(), 2u);
  EXPECT_EQ(frames.dropped(), 0u) << "a simulated sweep's frames wait for room";
  for (const FrameSweep& sweep : sweeps) {
    EXPECT_GT(sweep.frames.size(), 1u);
    EXPECT_GT(points_above_table(sweep, mine, half), 100u) << "the edit for this cell was not applied";
    EXPECT_EQ(points_above_table(sweep, theirs, half), 0u) << "the edit for another cell was applied";
  }
  EXPECT_EQ(refusals.count(), 1u);
  ASSERT_EQ(refusal_lines.size(), 1u);
  EXPECT_NE(refusal_lines[0].find("'far'"), std::string::npos) << refusal_lines[0];
  EXPECT_NE(refusal_lines[0].find("outside the cell"), std::string::npos) << refusal_lines[0];
  EXPECT_EQ(health.status().sensors[0].state, "streaming");
}

}  // namespace
}  // namespace cellmap::daemon
