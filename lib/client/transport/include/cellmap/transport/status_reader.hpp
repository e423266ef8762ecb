// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reads cellmap/status: the health reports of one cell's daemon or of every cell daemon on a domain.

#include <chrono>
#include <string>
#include <vector>

#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/messages.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::transport {

/// On joining it receives each cell's last report (transient local). `participant` must outlive it.
/// Not thread-safe.
class StatusReader final {
 public:
  /// Reads the partition of `cell`, or of every cell (kEveryCell).
  /// @throws Error if the reader cannot be created (e.g. DDS Security grants only one cell's partition).
  explicit StatusReader(const dds::Participant& participant, const std::string& cell = kEveryCell);
  ~StatusReader();
  StatusReader(const StatusReader&) = delete;
  StatusReader& operator=(const StatusReader&) = delete;
  /// Waits up to `timeout` (zero: just looks) and returns the reports received, oldest first. Malformed
  /// reports are skipped.
  std::vector<CellStatus> take(std::chrono::nanoseconds timeout = std::chrono::nanoseconds(0));
  /// The cells whose daemon is gone as of the last take(): its status writer left (a clean stop) or its
  /// lease expired (a crash: after the lease duration, Cyclone's default 10 s) after its last report, in the
  /// order seen. A cell that reported again later in the same take() is not listed.
  [[nodiscard]] const std::vector<std::string>& departed() const { return departed_; }

 private:
  dds::Topic topic_;
  dds::Reader reader_;
  dds::WaitSet waitset_;
  std::vector<std::string> departed_;
};

}  // namespace cellmap::transport
