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

TEST(DaemonBenchTest, FusesEveryFrameOfBothCamerasAtALowRate) {
  // 0.5 Hz for 8 s: 4 frames per camera, each pair a sweep; the first version after the first sweep, the
  // crate never appears. Two seconds per sweep leave room for the first version on a busy machine.
  const BenchRun run = run_bench("--rate 0.5 --seconds 8 --settle-sweeps 1 --warmup 100 --domain " +
                                 std::to_string(cellmap::test::domain::kBenchDaemon));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(number_after(run.output, "kinect +frames fused"), 4) << run.output;
  EXPECT_EQ(number_after(run.output, "realsense +frames fused"), 4) << run.output;
  EXPECT_EQ(number_after(run.output, "frames dropped:"), 0) << run.output;
  EXPECT_GE(number_after(run.output, "versions received by the subscriber:"), 1) << run.output;
  EXPECT_NE(run.output.find("ratio daemon fusion per frame (vs discretized insert): "), std::string::npos)
      << run.output;
}

TEST(DaemonBenchTest, OfflineScoresTheCrateBeforeEachOfItsChanges) {
  // 5 Hz for 14 s, the crate there from 6 to 10 s: the pipeline alone boxes it on its own while it stands and
  // frees its place once it is gone. No DDS here, so no domain.
  const BenchRun run =
      run_bench("--offline --rate 5 --seconds 14 --settle-sweeps 3 --warmup 6 --change-every 4");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_GE(number_after(run.output, "versions:"), 2) << run.output;
  EXPECT_NE(run.output.find("the crate boxed on its own 1 of 1 times, its place free 1 of 1 times"),
            std::string::npos)
      << run.output;
}

}  // namespace
