#pragma once
// Helpers for end-to-end tests of the service: cellmapd on the simulated cell as a real process (exact
// depths, a private state directory), `cellmap inject` as a process, and in-process planner subscribers.

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
#include "support/test_support.hpp"
#include "transport/child_process.hpp"
#include "transport/loopback.hpp"

namespace cellmap::test {

inline constexpr std::chrono::seconds kPatience{90};

/// A state directory and a config for cellmapd running the simulated cell under `cell` with exact depths:
/// these tests are about versions and deltas; noise robustness is tested where the noise is modelled.
/// `extra_yaml` is appended to the config; `state_dir` replaces the private one.
class ServiceFixture {
 public:
  explicit ServiceFixture(std::string cell, const std::string& extra_yaml = "",
                          std::optional<std::filesystem::path> state_dir = std::nullopt)
      : cell_(std::move(cell)), state_dir_(state_dir.value_or(dir_.path() / "state")) {
    config_ = dir_.path() / "cellmapd.yaml";
    std::ofstream(config_) << "cell: " << cell_
                           << "\nsweep_period: 0.2\nstatus_period: 0.5\nsource: {noise: false}\n"
                           << extra_yaml;
  }

  /// Starts cellmapd on `domain`. With `log_on_stdout` its log (stderr) is read through the ChildProcess.
  [[nodiscard]] std::unique_ptr<ChildProcess> start_daemon(int domain, bool log_on_stdout = false) const {
    std::vector<std::string> argv{
        CELLMAPD,      "--config",          config_.string(), "--domain", std::to_string(domain),
        "--state-dir", state_dir().string()};
    if (log_on_stdout) argv.insert(argv.begin(), {"/bin/sh", "-c", "exec \"$0\" \"$@\" 2>&1"});
    return std::make_unique<ChildProcess>(argv);
  }
  [[nodiscard]] const std::filesystem::path& state_dir() const { return state_dir_; }
  [[nodiscard]] const std::string& cell() const { return cell_; }

 private:
  std::string cell_;
  TempDir dir_;
  std::filesystem::path state_dir_;
  std::filesystem::path config_;
};

/// `cellmap inject --domain N ARGS...`; returns its first output line (add-box prints the new name).
inline std::string inject(int domain, const std::vector<std::string>& args) {
  std::vector<std::string> argv{CELLMAP_TOOL, "inject", "--domain", std::to_string(domain), "--wait", "60"};
  argv.insert(argv.end(), args.begin(), args.end());
  ChildProcess tool(argv);
  const std::string out = tool.read_line(kPatience).value_or("");
  EXPECT_EQ(tool.wait(), 0) << "cellmap inject failed";
  return out;
}

/// Waits until no new version came for `quiet` (the map has settled); returns the environment then.
inline Environment settled(const transport::EnvironmentSubscriber& planner, std::chrono::seconds quiet) {
  std::uint64_t version = planner.environment()->version();
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (std::chrono::steady_clock::now() < deadline) {
    if (!planner.wait_for_version(version + 1, quiet)) return *planner.environment();
    version = planner.environment()->version();
  }
  ADD_FAILURE() << "the environment never settled";
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
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (!boxed() && std::chrono::steady_clock::now() < deadline) {
    const std::uint64_t version = planner.environment() ? planner.environment()->version() : 0;
    planner.wait_for_version(version + 1, std::chrono::seconds(1));
  }
  return boxed();
}

/// Takes status reports of `cell` until one satisfies `accept` (returned) or the patience runs out.
inline std::optional<transport::CellStatus> wait_for_status(
    transport::StatusReader& reader, const std::string& cell,
    const std::function<bool(const transport::CellStatus&)>& accept) {
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (std::chrono::steady_clock::now() < deadline) {
    for (const transport::CellStatus& status : reader.take(std::chrono::milliseconds(200))) {
      if (status.cell == cell && accept(status)) return status;
    }
  }
  return std::nullopt;
}

/// An on_change callback that records every delta the subscriber applied.
class DeltaRecorder {
 public:
  void operator()(const Environment&, const EnvironmentDelta& delta) {
    std::lock_guard<std::mutex> lock(mutex_);
    deltas_.push_back(delta);
  }
  [[nodiscard]] EnvironmentDelta last() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return deltas_.back();
  }

 private:
  mutable std::mutex mutex_;
  std::vector<EnvironmentDelta> deltas_;
};

}  // namespace cellmap::test
