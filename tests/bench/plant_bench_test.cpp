// `cellmap bench plant` with two cells: both daemons, both planners and the monitor run as real processes on
// loopback, each planner gets its cell's snapshot, the changes of cell-1 reach its planner, and the planner
// of cell-2 counts what of cell-1 reached it. Speed is not asserted here.
#include <gtest/gtest.h>

#include <cstdio>
#include <regex>
#include <string>

#include "support/dds_domains.hpp"
#include "support/test_support.hpp"

namespace {

struct BenchRun {
  int exit_code = -1;
  std::string output;
};

BenchRun run_bench(const std::string& arguments) {
  const std::string command = std::string(CELLMAP_BENCH_PLANT) + " " + arguments + " 2>&1";
  BenchRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) run.output += buffer;
  run.exit_code = cellmap::test::exit_code(::pclose(pipe));
  return run;
}

// The number after `label` in `text`, or -1.
double number_after(const std::string& text, const std::string& label) {
  std::smatch match;
  if (!std::regex_search(text, match, std::regex(label + " *([0-9.]+)"))) return -1;
  return std::stod(match[1]);
}

TEST(PlantBenchTest, TwoCellsTheirPlannersAndAMonitor) {
  const BenchRun run = run_bench("--cells 2 --changes 2 --sweep-period 1 --timeout 60 --domain " +
                                 std::to_string(cellmap::test::domain::kBenchPlant));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("all 2 planners within"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("delta latency at cell-1's planner (2 changes)"), std::string::npos)
      << run.output;
  // The client library ignores foreign cells' samples, but today they reach it: one per change of cell-1.
  EXPECT_EQ(number_after(run.output, "at a planner of another cell:"), 1.0) << run.output;
  EXPECT_GT(number_after(run.output, "RSS per daemon: median"), 1.0) << run.output;
}

}  // namespace
