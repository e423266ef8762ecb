// SPDX-License-Identifier: Apache-2.0
#include "signals.hpp"

#include <pthread.h>

#include <cerrno>
#include <cstring>

#include "cellmap/common/error.hpp"

namespace cellmap::daemon {

Signals::Signals() {
  sigemptyset(&set_);
  sigaddset(&set_, SIGTERM);
  sigaddset(&set_, SIGINT);
  sigaddset(&set_, SIGHUP);
  const int rc = pthread_sigmask(SIG_BLOCK, &set_, nullptr);
  if (rc != 0) throw Error(std::string("cannot block signals: ") + std::strerror(rc));
}

std::optional<int> Signals::wait_for(std::chrono::milliseconds timeout) const {
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(timeout);
  timespec ts{};
  ts.tv_sec = seconds.count();
  ts.tv_nsec = std::chrono::duration_cast<std::chrono::nanoseconds>(timeout - seconds).count();
  for (;;) {
    const int signal_number = sigtimedwait(&set_, nullptr, &ts);
    if (signal_number >= 0) return signal_number;
    if (errno == EAGAIN) return std::nullopt;
    if (errno != EINTR) throw Error(std::string("waiting for signals failed: ") + std::strerror(errno));
  }
}

}  // namespace cellmap::daemon
