// SPDX-License-Identifier: Apache-2.0
// `cellmap bench fusion|segment|collision|dds|daemon|plant|ros2`: runs the benchmark program built beside
// this tool.
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "cellmap/common/error.hpp"
#include "commands.hpp"

namespace cellmap::cli {
namespace {

// The benchmark programs (cellmap-bench-NAME) are separate executables so that each links only what it
// measures; this command finds the one next to the running tool and replaces itself with it.
std::filesystem::path program_for(const std::string& name) {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error("bench: cannot locate the cellmap executable: " + ec.message());
  return self.parent_path() / ("cellmap-bench-" + name);
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto* sub = app.add_subcommand("bench", "Run a benchmark; prints 'ratio <name>: <N>x' against its anchor");
  auto name = std::make_shared<std::string>();
  auto extra = std::make_shared<std::vector<std::string>>();
  sub->add_option("name", *name, "fusion | segment | collision | dds | daemon | plant | ros2")
      ->required()
      ->check(CLI::IsMember({"fusion", "segment", "collision", "dds", "daemon", "plant", "ros2"}));
  sub->add_option("benchmark_flags", *extra, "extra Google Benchmark flags, e.g. --benchmark_filter=REGEX");
  sub->allow_extras(false);
  sub->callback([name, extra] {
    const std::filesystem::path program = program_for(*name);
    if (!std::filesystem::exists(program)) {
      throw Error("bench: " + program.string() +
                  " is not built (configure with -DCELLMAP_BUILD_BENCHMARKS=ON)");
    }
    std::vector<std::string> args{program.string()};
    args.insert(args.end(), extra->begin(), extra->end());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(program.c_str(), argv.data());
    throw Error("bench: cannot run " + program.string() + ": " + std::strerror(errno));
  });
}

}  // namespace cellmap::cli
