// SPDX-License-Identifier: Apache-2.0
#include "ratio_report.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>

namespace cellmap::bench {
namespace {

// Prints the usual console table and remembers each benchmark's real time per iteration.
class RecordingReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred) {
        failed_[run.benchmark_name()] = run.error_message;
      } else if (run.run_type == Run::RT_Iteration || run.aggregate_name == "median") {
        // With repetitions the median is the figure to compare; it overwrites the single runs.
        seconds_[run.run_name.str()] =
            run.GetAdjustedRealTime() / benchmark::GetTimeUnitMultiplier(run.time_unit);
      }
    }
  }
  std::map<std::string, double> seconds_;
  std::map<std::string, std::string> failed_;
};

}  // namespace

int run_and_report(int argc, char** argv, const std::vector<Ratio>& ratios) {
  benchmark::Initialize(&argc, argv);
  RecordingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();

  int status = 0;
  for (const auto& [name, reason] : reporter.failed_) {
    std::printf("benchmark %s failed: %s\n", name.c_str(), reason.c_str());
    status = 1;
  }
  for (const Ratio& ratio : ratios) {
    const auto ours = reporter.seconds_.find(ratio.ours);
    const auto anchor = reporter.seconds_.find(ratio.anchor);
    if (ours == reporter.seconds_.end() || anchor == reporter.seconds_.end()) {
      std::printf("ratio %s: not measured (%s or %s did not run)\n", ratio.name.c_str(), ratio.ours.c_str(),
                  ratio.anchor.c_str());
      status = 1;
      continue;
    }
    std::printf("ratio %s: %.2fx (ours %.6g s, anchor %.6g s)\n", ratio.name.c_str(),
                anchor->second / ours->second, ours->second, anchor->second);
  }
  std::fflush(stdout);
  return status;
}

}  // namespace cellmap::bench
