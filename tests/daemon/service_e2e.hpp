// SPDX-License-Identifier: Apache-2.0
#pragma once
// Helpers for end-to-end tests of the service: cellmapd on the simulated cell as a real process (exact
// depths, a private state directory), `cellmap inject` as a process, and in-process planner subscribers; all
// of them with DDS Security on when the test asks for it.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/transport/environment_subscriber.hpp"
#include "cellmap/transport/status_reader.hpp"
#include "support/test_credentials.hpp"
#include "support/test_support.hpp"
#include "transport/child_process.hpp"
#include "transport/loopback.hpp"

namespace cellmap::test {

/// How long a test waits on what a daemon it started does (a version, a status, a line of its log): longer
/// than kPatience, as the daemon first has to start, sweep and confirm; four times that in a sanitizer build,
/// whose daemon sweeps the simulated cell several times slower (under ASan, quiet: 0.3 s a sweep against the
/// release build's 0.2 s period, the first segmentation 2 s against 0.3 s, its first version after ≈ 8 s;
/// ThreadSanitizer and a loaded machine slow it further).
inline constexpr std::chrono::seconds kDaemonPatience{90 * kSanitizerSlowdown};

/// A state directory and a config for cellmapd running the simulated cell under `cell` with exact depths:
/// these tests are about versions and deltas; noise robustness is tested where the noise is modelled.
/// `extra_yaml` is appended to the config; `state_dir` replaces the private one.
///
/// With `secure_domain`, DDS Security is on for that domain: credentials are written for the cell, and the
/// daemon joins as daemon, inject as tool, planners (processes and participant()) as planner. The fixture
/// sets CYCLONEDDS_URI (loopback; the 10 s lease when secured), so make it before any participant.
class ServiceFixture {
 public:
  explicit ServiceFixture(std::string cell, const std::string& extra_yaml = "",
                          std::optional<std::filesystem::path> state_dir = std::nullopt,
                          std::optional<int> secure_domain = std::nullopt)
      : cell_(std::move(cell)), state_dir_(state_dir.value_or(dir_.path() / "state")) {
    config_ = dir_.path() / "cellmapd.yaml";
    std::ofstream(config_) << "cell: " << cell_
                           << "\nsweep_period: 0.2\nstatus_period: 0.5\nsource: {noise: false}\n"
                           << extra_yaml;
    if (secure_domain) credentials_.emplace(cell_, *secure_domain);
    if (secure_domain) {
      use_secure_loopback();
    } else {
      use_loopback();
    }
  }
  /// The default config, secured on `secure_domain` when it is given.
  ServiceFixture(std::string cell, std::optional<int> secure_domain)
      : ServiceFixture(std::move(cell), "", std::nullopt, secure_domain) {}

  /// Starts cellmapd on `domain`. With `log_on_stdout` its log (stderr) is read through the ChildProcess;
  /// `sweeps` > 0 passes --sweeps (the daemon stops after that many).
  [[nodiscard]] std::unique_ptr<ChildProcess> start_daemon(int domain, bool log_on_stdout = false,
                                                           std::uint64_t sweeps = 0) const {
    std::vector<std::string> argv{
        CELLMAPD,      "--config",          config_.string(), "--domain", std::to_string(domain),
        "--state-dir", state_dir().string()};
    if (sweeps > 0) argv.insert(argv.end(), {"--sweeps", std::to_string(sweeps)});
    append_flags(argv, security::Role::kDaemon);
    if (log_on_stdout) argv.insert(argv.begin(), {"/bin/sh", "-c", "exec \"$0\" \"$@\" 2>&1"});
    return std::make_unique<ChildProcess>(argv);
  }

  /// `cellmap inject --domain N ARGS...`; returns its first output line (add-box prints the new name).
  std::string inject(int domain, const std::vector<std::string>& args) const {
    std::vector<std::string> argv{CELLMAP_TOOL, "inject", "--domain", std::to_string(domain), "--wait", "60"};
    append_flags(argv, security::Role::kTool);
    argv.insert(argv.end(), args.begin(), args.end());
    ChildProcess tool(argv);
    const std::string out = tool.read_line(kDaemonPatience).value_or("");
    EXPECT_EQ(tool.wait(), 0) << "cellmap inject failed";
    return out;
  }

  /// A participant for an in-process planner (or observer) on `domain`.
  [[nodiscard]] dds::Participant participant(int domain) const {
    return dds::Participant(
        static_cast<std::uint32_t>(domain),
        credentials_ ? std::optional(credentials_->as(security::Role::kPlanner)) : std::nullopt);
  }
#ifdef CELLMAP_PLANNER
  /// The example planner's command line: `--domain N --cell C` and, when secured, its credentials.
  [[nodiscard]] std::vector<std::string> planner(int domain) const {
    std::vector<std::string> argv{CELLMAP_PLANNER, "--domain", std::to_string(domain), "--cell", cell_};
    append_flags(argv, security::Role::kPlanner);
    return argv;
  }
#endif

  [[nodiscard]] const std::filesystem::path& state_dir() const {
    return state_dir_;
  }
  /// The config file start_daemon() passes; a test may rewrite it (before the start, or before a SIGHUP).
  [[nodiscard]] const std::filesystem::path& config_file() const {
    return config_;
  }
  [[nodiscard]] const std::string& cell() const {
    return cell_;
  }
  [[nodiscard]] const std::optional<TestCredentials>& credentials() const {
    return credentials_;
  }

 private:
  void append_flags(std::vector<std::string>& argv, security::Role role) const {
    if (!credentials_) return;
    const std::vector<std::string> flags = credentials_->flags(role);
    argv.insert(argv.end(), flags.begin(), flags.end());
  }

  std::string cell_;
  TempDir dir_;
  std::filesystem::path state_dir_;
  std::filesystem::path config_;
  std::optional<TestCredentials> credentials_;
};

/// End-to-end tests that run twice, plain and with DDS Security on, are parameterized by this; each variant
/// has a domain of its own.
inline std::string security_name(const ::testing::TestParamInfo<bool>& info) {
  return info.param ? "Secure" : "Plain";
}

/// Takes status reports of `cell` until one satisfies `accept` (returned) or the patience runs out.
inline std::optional<transport::CellStatus> wait_for_status(
    transport::StatusReader& reader, const std::string& cell,
    const std::function<bool(const transport::CellStatus&)>& accept) {
  const auto deadline = std::chrono::steady_clock::now() + kDaemonPatience;
  while (std::chrono::steady_clock::now() < deadline) {
    for (const transport::CellStatus& status : reader.take(std::chrono::milliseconds(200))) {
      if (status.cell == cell && accept(status)) return status;
    }
  }
  return std::nullopt;
}

/// Waits until the daemon of `cell` reported `quiet_sweeps` sweeps in a row without a new version, at
/// `min_version` or later (the map settled); returns the status then. Counted in sweeps, not seconds, so a
/// slow run (a loaded machine, a sanitizer build) waits as many sweeps as a fast one. A restarted daemon
/// (its sweep count starts again) starts the count again.
inline std::optional<transport::CellStatus> wait_until_settled(transport::StatusReader& reader,
                                                               const std::string& cell,
                                                               std::uint64_t quiet_sweeps,
                                                               std::uint64_t min_version = 0) {
  std::optional<transport::CellStatus> since;  // the first report of the current version
  return wait_for_status(reader, cell, [&](const transport::CellStatus& status) {
    if (status.version < min_version) return false;
    if (!since || status.version != since->version || status.sweeps < since->sweeps) since = status;
    return status.sweeps >= since->sweeps + quiet_sweeps;
  });
}

/// Sweeps without a new version that show the map settled: 3 s at the fixture's 0.2 s sweep period.
inline constexpr std::uint64_t kQuietSweeps = 15;
/// The same after a start, while the first sweeps of a cell may still add to the map: 5 s at 0.2 s.
inline constexpr std::uint64_t kLongQuietSweeps = 25;

/// Waits until the map settled (wait_until_settled, at or above the subscriber's version) and the subscriber
/// holds that version; returns the environment then.
inline Environment settled(const transport::EnvironmentSubscriber& planner, transport::StatusReader& status,
                           const std::string& cell, std::uint64_t quiet_sweeps = kQuietSweeps) {
  const std::uint64_t held = planner.environment() ? planner.environment()->version() : 0;
  const std::optional<transport::CellStatus> quiet = wait_until_settled(status, cell, quiet_sweeps, held);
  if (!quiet) {
    ADD_FAILURE() << "the environment never settled";
  } else if (!planner.wait_for_version(quiet->version, kDaemonPatience)) {
    ADD_FAILURE() << "the subscriber never got the settled version " << quiet->version;
  }
  return *planner.environment();
}

/// Waits until some box of the subscriber's environment holds `p_C` (a box injected into the simulated cell
/// arrived, possibly after other versions); false if it did not within the patience.
inline bool wait_until_boxed(const transport::EnvironmentSubscriber& planner, const Eigen::Vector3d& p_C) {
  const auto boxed = [&] {
    const std::optional<Environment> env = planner.environment();
    return env && std::any_of(env->boxes().begin(), env->boxes().end(),
                              [&](const Box& box) { return box.contains(p_C); });
  };
  const auto deadline = std::chrono::steady_clock::now() + kDaemonPatience;
  while (!boxed() && std::chrono::steady_clock::now() < deadline) {
    const std::uint64_t version = planner.environment() ? planner.environment()->version() : 0;
    planner.wait_for_version(version + 1, std::chrono::seconds(1));
  }
  return boxed();
}

/// The log of a daemon started with `log_on_stdout`, read line by line as it comes. Every wait below keeps
/// reading, so the daemon never blocks on a full pipe while the test waits for something else.
class DaemonLog {
 public:
  explicit DaemonLog(ChildProcess& daemon) : daemon_(daemon) {}

  /// Reads what the daemon has logged so far.
  void drain() {
    while (std::optional<std::string> line = daemon_.read_line(std::chrono::milliseconds(0)))
      lines_.push_back(std::move(*line));
  }
  /// Reads until a line holding `text` comes (returned) or `patience` runs out or the daemon ended. Lines
  /// an earlier wait_for() went past are not searched again.
  std::optional<std::string> wait_for(const std::string& text,
                                      std::chrono::milliseconds patience = kDaemonPatience) {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    for (;;) {
      while (searched_ < lines_.size()) {
        const std::string& line = lines_[searched_++];
        if (line.find(text) != std::string::npos) return line;
      }
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      std::optional<std::string> line = daemon_.read_line(std::min(left, std::chrono::milliseconds(200)));
      if (line) {
        lines_.push_back(std::move(*line));
      } else if (!daemon_.running()) {
        return std::nullopt;
      }
    }
  }
  /// Lines read so far that hold `text`.
  [[nodiscard]] std::size_t count(const std::string& text) const {
    return static_cast<std::size_t>(std::count_if(lines_.begin(), lines_.end(), [&](const std::string& line) {
      return line.find(text) != std::string::npos;
    }));
  }
  [[nodiscard]] const std::vector<std::string>& lines() const { return lines_; }

 private:
  ChildProcess& daemon_;
  std::vector<std::string> lines_;
  std::size_t searched_ = 0;
};

/// wait_for_status() that reads the daemon's log meanwhile.
inline std::optional<transport::CellStatus> wait_for_status(
    transport::StatusReader& reader, const std::string& cell, DaemonLog& log,
    const std::function<bool(const transport::CellStatus&)>& accept,
    std::chrono::milliseconds patience = kDaemonPatience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  while (std::chrono::steady_clock::now() < deadline) {
    log.drain();
    for (const transport::CellStatus& status : reader.take(std::chrono::milliseconds(200))) {
      if (status.cell == cell && accept(status)) return status;
    }
  }
  return std::nullopt;
}

/// planner.wait_for_version() that reads the daemon's log meanwhile.
inline bool wait_for_version(const transport::EnvironmentSubscriber& planner, std::uint64_t version,
                             DaemonLog& log, std::chrono::milliseconds patience = kDaemonPatience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  while (std::chrono::steady_clock::now() < deadline) {
    log.drain();
    if (planner.wait_for_version(version, std::chrono::milliseconds(200))) return true;
  }
  return false;
}

/// An on_change callback that records every delta the subscriber applied.
class DeltaRecorder {
 public:
  void operator()(const Environment&, const EnvironmentDelta& delta) {
    std::lock_guard<std::mutex> lock(mutex_);
    deltas_.push_back(delta);
  }
  /// The delta that led to `version` (picked by to_version: later versions may have come since).
  [[nodiscard]] EnvironmentDelta to(std::uint64_t version) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const EnvironmentDelta& delta : deltas_) {
      if (delta.to_version == version) return delta;
    }
    ADD_FAILURE() << "no delta to version " << version;
    return {};
  }

 private:
  mutable std::mutex mutex_;
  std::vector<EnvironmentDelta> deltas_;
};

}  // namespace cellmap::test
