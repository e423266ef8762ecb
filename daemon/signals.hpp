// SPDX-License-Identifier: Apache-2.0
#pragma once
// Signal handling for cellmapd: signals are blocked in every thread and taken synchronously by the main
// thread, so no handler ever runs inside library code.

#include <signal.h>

#include <chrono>
#include <optional>

namespace cellmap::daemon {

/// Blocks SIGTERM, SIGINT and SIGHUP for the calling thread and every thread it starts afterwards; construct
/// it in main() before starting threads. wait_for() then takes them one at a time.
class Signals final {
 public:
  Signals();
  Signals(const Signals&) = delete;
  Signals& operator=(const Signals&) = delete;

  /// Waits up to `timeout` for one of the blocked signals; returns its number, or nothing on timeout.
  [[nodiscard]] std::optional<int> wait_for(std::chrono::milliseconds timeout) const;

 private:
  sigset_t set_{};
};

}  // namespace cellmap::daemon
