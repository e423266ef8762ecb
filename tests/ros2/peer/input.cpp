// SPDX-License-Identifier: Apache-2.0
#include "input.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace ros2_peer {

Signals::Signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  if (pthread_sigmask(SIG_BLOCK, &set, nullptr) != 0) throw std::runtime_error("cannot block SIGTERM/SIGINT");
  fd_ = signalfd(-1, &set, SFD_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error(std::string("signalfd: ") + std::strerror(errno));
}

Signals::~Signals() {
  ::close(fd_);
}

bool Signals::raised() {
  poll(-1, 0);
  return raised_;
}

bool Signals::sleep_for(std::chrono::nanoseconds duration) {
  const auto deadline = std::chrono::steady_clock::now() + duration;
  while (!raised_) {
    const auto left =
        std::chrono::ceil<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return true;
    poll(-1, static_cast<int>(std::min<std::chrono::milliseconds::rep>(left.count(), 1000)));
  }
  return false;
}

bool Signals::wait_readable(int fd) {
  while (!raised_) {
    if (poll(fd, -1)) return true;
  }
  return false;
}

bool Signals::poll(int fd, int timeout_ms) {
  pollfd fds[2] = {{fd_, POLLIN, 0}, {fd, POLLIN, 0}};
  const int ready = ::poll(fds, fd >= 0 ? 2 : 1, timeout_ms);
  if (ready <= 0) return false;  // timeout, or EINTR from a signal we do not handle: look again
  if (fds[0].revents & POLLIN) {
    signalfd_siginfo info;
    if (::read(fd_, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) raised_ = true;
  }
  // POLLHUP without POLLIN: the writer closed; read() then reports the end.
  return fd >= 0 && (fds[1].revents & (POLLIN | POLLHUP | POLLERR)) != 0;
}

bool Input::fill() {
  if (!signals_.wait_readable(fd_)) return false;
  char chunk[65536];
  const ssize_t n = ::read(fd_, chunk, sizeof chunk);
  if (n < 0 && (errno == EINTR || errno == EAGAIN)) return true;
  if (n <= 0) return false;
  if (start_ > 0) {
    buffer_.erase(0, start_);
    start_ = 0;
  }
  buffer_.append(chunk, static_cast<std::size_t>(n));
  return true;
}

std::optional<std::string> Input::line() {
  for (;;) {
    const auto newline = buffer_.find('\n', start_);
    if (newline != std::string::npos) {
      std::string line = buffer_.substr(start_, newline - start_);
      start_ = newline + 1;
      return line;
    }
    if (!fill()) {
      // A last line without '\n' still counts.
      if (start_ >= buffer_.size() || signals_.raised()) return std::nullopt;
      std::string line = buffer_.substr(start_);
      start_ = buffer_.size();
      return line;
    }
  }
}

bool Input::bytes(std::size_t count, std::vector<std::uint8_t>& out) {
  const std::size_t buffered = std::min(count, buffer_.size() - start_);
  out.insert(out.end(), buffer_.begin() + static_cast<std::ptrdiff_t>(start_),
             buffer_.begin() + static_cast<std::ptrdiff_t>(start_ + buffered));
  start_ += buffered;
  std::size_t missing = count - buffered;
  // The rest straight into `out`: a 640x480 cloud is megabytes.
  const std::size_t end = out.size();
  out.resize(end + missing);
  std::size_t at = end;
  while (missing > 0) {
    if (!signals_.wait_readable(fd_)) return false;
    const ssize_t n = ::read(fd_, out.data() + at, missing);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) {
      out.resize(at);
      return false;
    }
    at += static_cast<std::size_t>(n);
    missing -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace ros2_peer
