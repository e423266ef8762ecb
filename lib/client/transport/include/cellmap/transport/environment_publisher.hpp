// SPDX-License-Identifier: Apache-2.0
#pragma once
// The daemon side of cellmap/environment, cellmap/environment_delta and cellmap/status for one cell.

#include <cstdint>
#include <string>

#include "cellmap/environment/environment.hpp"
#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/messages.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::transport {

/// Publishes the versions of one cell. Each version goes out as its delta first, then the snapshot, so a
/// subscriber in sync applies the small delta as soon as it arrives; the snapshot (KEEP_LAST 1, transient
/// local) is there for late joiners and resyncs. The writers do not dispose their instances when deleted:
/// a restarted daemon does not look like "all boxes removed" to subscribers.
///
/// `participant` must outlive the publisher. Not thread-safe (one publishing thread).
class EnvironmentPublisher final {
 public:
  /// Writes into the cell's partition (topics.hpp).
  /// @param delta_depth the delta history kept for late joiners (KEEP_LAST), >= 1.
  /// @throws Error if a writer cannot be created, delta_depth is 0, or `cell` is not one valid cell id.
  EnvironmentPublisher(const dds::Participant& participant, std::string cell,
                       std::uint32_t delta_depth = kDefaultDeltaDepth);

  /// Publishes a version without a delta from the previous one: at start or restart (the loaded version), or
  /// after versions that were not published. It goes out as a delta from version 0 (every box added), which
  /// subscribers in sync take as a snapshot, and as the snapshot.
  /// @throws Error if env is of another cell, is version 0 or not above the last published.
  void publish(const Environment& env);
  /// Publishes `delta` (to env's version), then `env`. @throws Error as above, or if the delta is of another
  /// cell or does not end at env.version().
  void publish(const Environment& env, const EnvironmentDelta& delta);
  /// @throws Error if status.cell is not this publisher's cell or the write fails.
  void publish_status(const CellStatus& status);

  /// Blocks until `count` readers of the delta topic (every subscriber and monitor has one) matched or the
  /// timeout passed; true if they did.
  bool wait_for_subscribers(std::uint32_t count, std::chrono::nanoseconds timeout) const;
  /// As above for readers of the snapshot topic (monitors, and subscribers while they need a snapshot):
  /// the two topics' readers match independently, so a sample written before its topic matched reaches a
  /// late reader only as that topic's history.
  bool wait_for_snapshot_readers(std::uint32_t count, std::chrono::nanoseconds timeout) const;
  /// How many readers of the delta topic ever matched (grows by one per subscriber that joins).
  [[nodiscard]] std::uint32_t subscribers_joined() const;

  [[nodiscard]] const std::string& cell() const { return cell_; }
  /// The last version published, 0 before the first.
  [[nodiscard]] std::uint64_t last_version() const { return last_version_; }

 private:
  void check_version(const Environment& env) const;

  std::string cell_;
  dds::Topic snapshot_topic_;
  dds::Topic delta_topic_;
  dds::Topic status_topic_;
  dds::Writer snapshot_writer_;
  dds::Writer delta_writer_;
  dds::Writer status_writer_;
  std::uint64_t last_version_ = 0;
};

}  // namespace cellmap::transport
