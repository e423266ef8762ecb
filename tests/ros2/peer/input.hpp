// SPDX-License-Identifier: Apache-2.0
#pragma once
// ros2_peer's input: command lines and raw payloads from stdin, and SIGTERM/SIGINT. Both come through one
// poll(), so a signal ends a blocked read, a sleep or a wait at once and the peer still leaves DDS cleanly
// (a signal handler could not delete DDS entities; a thread of Fast DDS could take the signal instead).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace ros2_peer {

/// SIGTERM and SIGINT as a file descriptor (signalfd). Construct it before any other thread starts (before
/// the DDS participant): it blocks both signals in the calling thread, and threads inherit that.
class Signals final {
 public:
  Signals();
  ~Signals();
  Signals(const Signals&) = delete;
  Signals& operator=(const Signals&) = delete;

  /// True once SIGTERM or SIGINT arrived (checks without waiting).
  [[nodiscard]] bool raised();
  /// Sleeps for `duration` unless a signal arrives first; returns false then.
  bool sleep_for(std::chrono::nanoseconds duration);
  /// Waits until `fd` is readable (true) or a signal arrives (false).
  bool wait_readable(int fd);

 private:
  // Polls the signal descriptor (and `fd` when >= 0) for up to `timeout_ms` (-1: forever); true when `fd`
  // is readable.
  bool poll(int fd, int timeout_ms);
  int fd_ = -1;
  bool raised_ = false;
};

/// Reads stdin: lines, then for a command with bytes=N exactly N raw bytes.
class Input final {
 public:
  explicit Input(Signals& signals, int fd = 0) : signals_(signals), fd_(fd) {}

  /// The next line without its '\n', or nullopt at end of input or on a signal.
  std::optional<std::string> line();
  /// Appends exactly `count` bytes to `out`; false at end of input (or on a signal) before all came.
  bool bytes(std::size_t count, std::vector<std::uint8_t>& out);

 private:
  // Reads what is there into buffer_; false at end of input or on a signal.
  bool fill();
  Signals& signals_;
  int fd_;
  std::string buffer_;
  std::size_t start_ = 0;  // buffer_ before start_ is consumed
};

}  // namespace ros2_peer
