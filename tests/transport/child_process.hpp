// SPDX-License-Identifier: Apache-2.0
#pragma once
// A child process for end-to-end tests: started with execv, its stdout read line by line with a timeout;
// optionally its stdin written by the test.

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace cellmap::test {

class ChildProcess {
 public:
  /// What the child reads: the test's stdin, or what the test writes with write_input().
  enum class Input { inherit, from_test };

  explicit ChildProcess(std::vector<std::string> argv, Input input = Input::inherit) {
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("pipe failed");
    // A socket rather than a pipe for stdin: writing to a child that died then fails with EPIPE (send with
    // MSG_NOSIGNAL) instead of killing the test with SIGPIPE.
    int in[2] = {-1, -1};
    if (input == Input::from_test && ::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, in) != 0) {
      throw std::runtime_error("socketpair failed");
    }
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      ::dup2(fds[1], STDOUT_FILENO);
      ::close(fds[0]);
      ::close(fds[1]);
      if (in[1] >= 0) ::dup2(in[1], STDIN_FILENO);  // dup2 clears CLOEXEC on the copy
      std::vector<char*> args;
      for (std::string& a : argv) args.push_back(a.data());
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
    ::close(fds[1]);
    out_ = fds[0];
    if (in[1] >= 0) ::close(in[1]);
    in_ = in[0];
  }
  ~ChildProcess() {
    close_input();
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      wait();
    }
    if (out_ >= 0) ::close(out_);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  /// The next line of the child's stdout (without '\n'), or nullopt on timeout or end of output. A zero
  /// timeout returns a line only if one is already there.
  std::optional<std::string> read_line(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto newline = buffer_.find('\n');
      if (newline != std::string::npos) {
        std::string line = buffer_.substr(0, newline);
        buffer_.erase(0, newline + 1);
        return line;
      }
      if (out_ < 0) return std::nullopt;
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      pollfd p{out_, POLLIN, 0};
      // Polls at least once, so a zero timeout still picks up what is already there.
      if (::poll(&p, 1, static_cast<int>(std::max<std::int64_t>(left.count(), 0))) <= 0) {
        if (left.count() <= 0) return std::nullopt;
        continue;
      }
      char chunk[4096];
      const ssize_t n = ::read(out_, chunk, sizeof chunk);
      if (n <= 0) {
        ::close(out_);
        out_ = -1;
        continue;
      }
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }

  /// Writes all of `data` to the child's stdin (Input::from_test); blocks while the child does not read.
  /// @throws std::runtime_error if the child's stdin is closed or the child is gone.
  void write_input(std::string_view data) {
    while (!data.empty()) {
      const ssize_t n = in_ < 0 ? -1 : ::send(in_, data.data(), data.size(), MSG_NOSIGNAL);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw std::runtime_error("cannot write to the child's stdin");
      data.remove_prefix(static_cast<std::size_t>(n));
    }
  }

  /// Ends the child's stdin: it reads end of file.
  void close_input() {
    if (in_ >= 0) ::close(in_);
    in_ = -1;
  }

  void signal(int sig) const {
    if (pid_ > 0) ::kill(pid_, sig);
  }

  /// True while the child has not ended (it is not reaped: wait() still returns its status).
  [[nodiscard]] bool running() const {
    if (pid_ <= 0) return false;
    siginfo_t info{};
    if (::waitid(P_PID, static_cast<id_t>(pid_), &info, WEXITED | WNOHANG | WNOWAIT) != 0) return false;
    return info.si_pid == 0;
  }

  /// Waits for the child to end; returns its wait status.
  int wait() {
    int status = 0;
    if (pid_ > 0) ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return status;
  }

 private:
  pid_t pid_ = -1;
  int out_ = -1;
  int in_ = -1;
  std::string buffer_;
};

}  // namespace cellmap::test
