// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the benchmarks that time DDS share: loopback-only Cyclone settings, and a subscriber process reporting
// each version it received to its parent, stamped on CLOCK_MONOTONIC (comparable across processes).

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

namespace cellmap::bench {

/// Loopback unicast only, as in the tests; used when the caller did not configure Cyclone.
inline constexpr const char* kLoopbackConfig =
    "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface "
    "address=\"127.0.0.1\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
    "<Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery></Domain></CycloneDDS>";

/// Nanoseconds on std::chrono::steady_clock (CLOCK_MONOTONIC on Linux).
inline std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// What the subscriber process reports for each version it received.
struct Arrival {
  std::uint64_t version;
  std::int64_t received_ns;
};

/// In the subscriber process: writes the arrival of `version`, now, to stdout (a pipe to the parent); exits
/// if the parent is gone.
inline void report_arrival(std::uint64_t version) {
  const Arrival arrival{version, now_ns()};
  if (::write(STDOUT_FILENO, &arrival, sizeof arrival) != sizeof arrival) std::_Exit(3);
}

/// This benchmark program run again as a child with `arguments` (argv[0] first), its stdout a pipe whose read
/// end in_fd() gives: the subscriber side of a benchmark. Killed (SIGKILL) and reaped by stop() or on
/// destruction; the pipe closes with it.
class ReportingChild {
 public:
  explicit ReportingChild(const std::vector<std::string>& arguments) {
    int fds[2];
    if (::pipe(fds) != 0) std::abort();
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fds[1], STDOUT_FILENO);
      ::close(fds[0]);
      ::close(fds[1]);
      std::vector<char*> argv;
      for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
      argv.push_back(nullptr);
      ::execv("/proc/self/exe", argv.data());
      std::_Exit(127);
    }
    ::close(fds[1]);
    in_ = fds[0];
  }
  ~ReportingChild() {
    stop();
    ::close(in_);
  }
  ReportingChild(const ReportingChild&) = delete;
  ReportingChild& operator=(const ReportingChild&) = delete;

  [[nodiscard]] int in_fd() const { return in_; }
  /// The child's process id (-1 once stopped).
  [[nodiscard]] pid_t pid() const { return pid_; }
  /// Ends the child (once): a reader of in_fd() then sees end of file.
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
  int in_ = -1;
};

}  // namespace cellmap::bench
