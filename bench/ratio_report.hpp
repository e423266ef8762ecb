// SPDX-License-Identifier: Apache-2.0
#pragma once
// Shared main for cellmap's Google Benchmark programs: runs the registered benchmarks, then prints each
// configured comparison as "ratio <name>: <anchor time / our time>x", both measured in this same run.

#include <string>
#include <vector>

namespace cellmap::bench {

/// One comparison: `ours` and `anchor` are benchmark names as Google Benchmark reports them
/// (e.g. "BM_FusionOurs/frames:3"). A ratio above 1 means ours is faster.
struct Ratio {
  std::string name;
  std::string ours;
  std::string anchor;
};

/// Runs the benchmarks (argv may carry --benchmark_* flags), prints the normal console report, then one
/// ratio line per entry of `ratios` whose two benchmarks both ran. Returns the process exit code: 1 if a
/// ratio's benchmarks did not both run or reported an error.
int run_and_report(int argc, char** argv, const std::vector<Ratio>& ratios);

}  // namespace cellmap::bench
