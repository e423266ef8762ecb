// SPDX-License-Identifier: Apache-2.0
#pragma once
// Small helpers shared by the tests.

#include <stdio.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap::test {

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define CELLMAP_TEST_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define CELLMAP_TEST_SANITIZED 1
#endif
/// How many times longer a test waits in a sanitizer build (ASan, TSan) than in a plain one.
#ifdef CELLMAP_TEST_SANITIZED
inline constexpr int kSanitizerSlowdown = 4;
#else
inline constexpr int kSanitizerSlowdown = 1;
#endif

/// How long a test waits for what it can observe (a reader matched, a sample, an ack): generous, as the
/// machine is shared; passing runs take milliseconds.
inline constexpr std::chrono::seconds kPatience{30};

/// A fresh directory under the system temp folder, removed with everything in it when the object goes.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "cellmap-test") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    path_ = ::mkdtemp(pattern.data());
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// The exit code of a child process from its wait status (waitpid, pclose, std::system), or -1 when a signal
/// ended it: a check `exit_code(status) == 0` fails on a crash, which `WEXITSTATUS(status) == 0` alone
/// passes.
inline int exit_code(int wait_status) {
  return WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1;
}

/// What a program printed and how it ended.
struct CommandRun {
  std::string output;
  int status = -1;  ///< exit code, -1 when a signal ended it
};

/// Runs `command` through /bin/sh and reads its stdout (add `2>&1` to read its stderr too).
inline CommandRun run_command(const std::string& command) {
  CommandRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  while (::fgets(buffer, sizeof buffer, pipe) != nullptr) run.output += buffer;
  run.status = exit_code(::pclose(pipe));
  return run;
}

/// The message of the cellmap::Error that `f` throws, or "" if it throws none.
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// An input with which a fuzzer (fuzz/) found a bug, kept as a regression input:
/// fuzz/regressions/<target>/<name> of the source tree.
inline std::string fuzz_regression(const std::string& target, const std::string& name) {
  return std::string(CELLMAP_SOURCE_DIR) + "/fuzz/regressions/" + target + "/" + name;
}

/// The message of the cellmap::Error that `f` throws, checked to be one line (gtest failure otherwise); "" if
/// it throws none.
inline std::string one_line_error_of(const std::function<void()>& f) {
  const std::string message = error_of(f);
  if (message.find('\n') != std::string::npos) ADD_FAILURE() << "not one line: " << message;
  return message;
}

}  // namespace cellmap::test
