#pragma once
// Reads cellmap/status: the health reports of every cell daemon on a domain.

#include <chrono>
#include <vector>

#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/messages.hpp"

namespace cellmap::transport {

/// On joining it receives each cell's last report (transient local). `participant` must outlive it.
/// Not thread-safe.
class StatusReader final {
 public:
  /// @throws Error if the reader cannot be created.
  explicit StatusReader(const dds::Participant& participant);
  ~StatusReader();
  StatusReader(const StatusReader&) = delete;
  StatusReader& operator=(const StatusReader&) = delete;
  /// Waits up to `timeout` (zero: just looks) and returns the reports received, oldest first. Malformed
  /// reports are skipped.
  std::vector<CellStatus> take(std::chrono::nanoseconds timeout = std::chrono::nanoseconds(0));

 private:
  dds::Topic topic_;
  dds::Reader reader_;
  dds::WaitSet waitset_;
};

}  // namespace cellmap::transport
