// SPDX-License-Identifier: Apache-2.0
#pragma once
// Watches every snapshot and delta on a domain, of every cell, as they arrive (what `cellmap echo` prints).

#include <chrono>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "cellmap/environment/environment.hpp"
#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::transport {

using EnvironmentMessage = std::variant<Environment, EnvironmentDelta>;

/// Raw reader of cellmap/environment and cellmap/environment_delta (no bookkeeping), of one cell's partition
/// or of every cell's (kEveryCell). On joining it receives each cell's current snapshot and up to
/// `delta_depth` recent deltas (transient local).
/// `participant` must outlive it. Not thread-safe.
class EnvironmentMonitor final {
 public:
  /// @throws Error if a reader cannot be created (e.g. DDS Security grants only one cell's partition) or
  /// the cell id is not valid (cell_partition).
  explicit EnvironmentMonitor(const dds::Participant& participant, const std::string& cell = kEveryCell,
                              std::uint32_t delta_depth = kDefaultDeltaDepth);
  ~EnvironmentMonitor();
  EnvironmentMonitor(const EnvironmentMonitor&) = delete;
  EnvironmentMonitor& operator=(const EnvironmentMonitor&) = delete;

  /// Waits up to `timeout` for samples, then returns all received, ordered by the time they were written.
  /// Malformed samples are skipped and counted (rejected(), last_rejection()).
  std::vector<EnvironmentMessage> take(std::chrono::nanoseconds timeout);

  [[nodiscard]] std::uint64_t rejected() const { return rejected_; }
  [[nodiscard]] const std::string& last_rejection() const { return last_rejection_; }

 private:
  dds::Topic snapshot_topic_;
  dds::Topic delta_topic_;
  dds::Reader snapshot_reader_;
  dds::Reader delta_reader_;
  dds::WaitSet waitset_;
  std::uint64_t rejected_ = 0;
  std::string last_rejection_;
};

}  // namespace cellmap::transport
