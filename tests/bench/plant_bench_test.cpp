// SPDX-License-Identifier: Apache-2.0
// `cellmap bench plant` with two cells: both daemons, both planners and the monitor run as real processes on
// loopback, each planner gets its cell's snapshot, the changes of cell-1 reach its planner, and the planner
// of cell-2 counts what of cell-1 reached it. Speed is not asserted here.
#include <gtest/gtest.h>

#include <string>

#include "bench/bench_run.hpp"
#include "support/dds_domains.hpp"

namespace {

using cellmap::test::BenchRun;
using cellmap::test::number_after;

BenchRun run_bench(const std::string& arguments) {
  return cellmap::test::run_bench(CELLMAP_BENCH_PLANT, arguments);
}

TEST(PlantBenchTest, TwoCellsTheirPlannersAndAMonitor) {
  const BenchRun run = run_bench("--cells 2 --changes 2 --sweep-period 1 --timeout 60 --domain " +
                                 std::to_string(cellmap::test::domain::kBenchPlant));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("all 2 planners within"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("delta latency at cell-1's planner (2 changes)"), std::string::npos)
      << run.output;
  // Each cell in its own partition: none of cell-1's samples reach cell-2's planner, at joining neither.
  EXPECT_EQ(number_after(run.output, "at a planner of another cell:"), 0.0) << run.output;
  EXPECT_EQ(number_after(run.output, "payload each\\), "), 0.0) << run.output;
  EXPECT_GT(number_after(run.output, "RSS per daemon: median"), 1.0) << run.output;
}

}  // namespace
