// SPDX-License-Identifier: Apache-2.0
#pragma once
// The DDS inputs cellmapd refused (scene edits, robot poses): counted for cellmap/status and logged, at most
// one line a second so that a flood of bad samples cannot flood the log; and the budget that keeps the lines
// of accepted inputs (applied scene edits) from flooding it either.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

namespace cellmap::daemon {

/// Thread-safe: readers on the acquisition thread refuse, the processing thread reads count().
class InputRefusals final {
 public:
  using Clock = std::chrono::steady_clock;
  using Log = std::function<void(const std::string& line)>;

  /// @param log       receives each line (cellmapd: a warning)
  /// @param interval  the shortest time between two lines
  explicit InputRefusals(Log log, Clock::duration interval = std::chrono::seconds(1));

  /// Counts one refusal; logs "refused: <reason> (<N> inputs refused so far)" unless a line went out less
  /// than `interval` ago. Refusals in between are counted, and the next line's total includes them.
  void refuse(const std::string& reason, Clock::time_point now = Clock::now());
  [[nodiscard]] std::uint64_t count() const { return count_; }

 private:
  Log log_;
  Clock::duration interval_;
  std::atomic<std::uint64_t> count_{0};
  std::mutex mutex_;
  std::optional<Clock::time_point> last_line_;  // guarded by mutex_
};

/// At most `lines` log lines per `interval` of one kind of input; lines beyond are held back and counted, and
/// the next line that goes out says how many. Not thread-safe: one thread logs.
class LogBudget final {
 public:
  using Clock = std::chrono::steady_clock;
  LogBudget(std::size_t lines, Clock::duration interval);
  /// `line`, with " (K more not logged)" when K were held back since the last one, or nullopt: hold it back.
  [[nodiscard]] std::optional<std::string> admit(const std::string& line,
                                                 Clock::time_point now = Clock::now());

 private:
  std::size_t lines_;
  Clock::duration interval_;
  std::optional<Clock::time_point> window_start_;
  std::size_t in_window_ = 0;
  std::uint64_t held_back_ = 0;
};

}  // namespace cellmap::daemon
