// SPDX-License-Identifier: Apache-2.0
#pragma once
// Running a benchmark program from a test: its exit code and output, and the numbers it prints.

#include <cstdio>
#include <regex>
#include <string>

#include "support/test_support.hpp"

namespace cellmap::test {

struct BenchRun {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr
};

inline BenchRun run_bench(const std::string& program, const std::string& arguments) {
  const std::string command = program + " " + arguments + " 2>&1";
  BenchRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) run.output += buffer;
  run.exit_code = exit_code(::pclose(pipe));
  return run;
}

/// The number after `label` (a regex) in `text`, or -1.
inline double number_after(const std::string& text, const std::string& label) {
  std::smatch match;
  if (!std::regex_search(text, match, std::regex(label + " *([0-9]+(\\.[0-9]+)?)"))) return -1;
  return std::stod(match[1]);
}

}  // namespace cellmap::test
