// SPDX-License-Identifier: Apache-2.0
// `cellmap bench daemon` at a low frame rate: the bench runs cellmapd's path end to end, fuses every frame
// of both cameras and its subscriber receives the versions it publishes. Speed is not asserted here.
#include <gtest/gtest.h>

#include <string>

#include "bench/bench_run.hpp"
#include "support/dds_domains.hpp"

namespace {

using cellmap::test::BenchRun;
using cellmap::test::number_after;

BenchRun run_bench(const std::string& arguments) {
  return cellmap::test::run_bench(CELLMAP_BENCH_DAEMON, arguments);
}

TEST(DaemonBenchTest, FusesTheFramesOfBothCamerasAndPublishesAtALowRate) {
  // 0.5 Hz for 8 s: 4 frames per camera, each pair a sweep; the first version after the first sweep, the
  // crate never appears. How many frames are fused before the 8 s end is the bench's measurement, not
  // asserted: with CPU hogs on both cores the replays' readers (SCHED_IDLE) starve for seconds and the last
  // frames come after the run (realsense 2 of 4, 2 counted dropped). Asserted: frames of both cameras go
  // through cellmapd's path, none is fused twice, and the subscriber receives the versions.
  const BenchRun run = run_bench("--rate 0.5 --seconds 8 --settle-sweeps 1 --warmup 100 --domain " +
                                 std::to_string(cellmap::test::domain::kBenchDaemon));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const std::string camera : {"kinect", "realsense"}) {
    EXPECT_GE(number_after(run.output, camera + " +frames fused"), 1) << run.output;
    EXPECT_LE(number_after(run.output, camera + " +frames fused"), 4) << run.output;
  }
  const double dropped = number_after(run.output, "frames dropped:");
  EXPECT_GE(dropped, 0) << run.output;
  EXPECT_LE(dropped, 6) << run.output;  // at least one frame of each camera fused
  EXPECT_GE(number_after(run.output, "versions received by the subscriber:"), 1) << run.output;
  EXPECT_NE(run.output.find("ratio daemon fusion per frame (vs discretized insert): "), std::string::npos)
      << run.output;
}

TEST(DaemonBenchTest, OfflineScoresTheCrateBeforeEachOfItsChangesPerPhaseAndOverAll) {
  // 5 Hz for 14 s, the crate there from 6 to 10 s, two places of the sweeps in the gantry's passes: the
  // pipeline alone boxes it on its own while it stands and, at phase 0, frees its place once it is gone; the
  // overall line adds the phases up. The map settles for 3 sweeps only, so versions are many: the criteria
  // are the long run's (docs/tuning.md). No DDS here, so no domain.
  const BenchRun run =
      run_bench("--offline --rate 5 --seconds 14 --settle-sweeps 3 --warmup 6 --change-every 4 --phases 0,3");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string phase0 = run.output.substr(run.output.rfind("phase 0: "));
  EXPECT_NE(phase0.find("the crate boxed on its own 1 of 1 times, its place free 1 of 1 times"),
            std::string::npos)
      << run.output;
  const double versions0 = number_after(phase0, "phase 0:");
  const double versions3 = number_after(run.output.substr(run.output.rfind("phase 3: ")), "phase 3:");
  ASSERT_GE(versions0, 1) << run.output;
  ASSERT_GE(versions3, 1) << run.output;
  const std::string overall = run.output.substr(run.output.rfind("over 2 phases: "));
  EXPECT_NEAR(number_after(overall, "over 2 phases:"), (versions0 + versions3) / 4, 0.006)
      << "2 changes of the crate in each phase\n"
      << run.output;
  EXPECT_NE(overall.find("the crate boxed on its own 2 of 2 times"), std::string::npos) << run.output;
  EXPECT_GT(number_after(overall, "on average and"), 0) << run.output;
}

}  // namespace
