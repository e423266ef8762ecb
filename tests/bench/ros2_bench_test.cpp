// SPDX-License-Identifier: Apache-2.0
// `cellmap bench ros2` for a second per input variant: both conversions agree, both ratio lines and every
// input line are printed, every writer published at 30 Hz and the clouds a writer in the same process
// publishes reach the source. Speed, and how many clouds cross loopback UDP, are not asserted here.
#include <gtest/gtest.h>

#include <string>

#include "bench/bench_run.hpp"
#include "support/dds_domains.hpp"

namespace {

using cellmap::test::BenchRun;
using cellmap::test::number_after;

TEST(Ros2BenchTest, PrintsBothRatiosAndEveryInputVariant) {
  const BenchRun run =
      cellmap::test::run_bench(CELLMAP_BENCH_ROS2, "--seconds 1 --benchmark_min_time=0.01 --domain " +
                                                       std::to_string(cellmap::test::domain::kBenchRos2));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("848x480: 848 x 480, point_step 32"), std::string::npos) << run.output;
  EXPECT_GT(number_after(run.output, "ratio ros2 pointcloud2 848x480:"), 0.0) << run.output;
  EXPECT_GT(number_after(run.output, "ratio ros2 pointcloud2 lidar:"), 0.0) << run.output;
  for (const char* variant : {"best_effort", "reliable writer, best_effort reader", "reliable"}) {
    const std::string line = std::string("ros2 input 848x480 @30 Hz \\(") + variant + "\\):";
    EXPECT_EQ(number_after(run.output, line), 30.0) << variant << "\n" << run.output;  // frames sent
  }
  const std::string in_process = "ros2 input 848x480 @30 Hz \\(best_effort, writer in this process\\):";
  EXPECT_EQ(number_after(run.output, in_process), 30.0) << run.output;
  EXPECT_GE(number_after(run.output, in_process + " 30 sent,"), 1.0) << run.output;  // frames received
}

}  // namespace
