// SPDX-License-Identifier: Apache-2.0
#pragma once
// The planner client: subscribe to one cell and keep a local copy of its environment current.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/environment_tracker.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::transport {

/// Follows one cell: applies deltas in order, resyncs from the snapshot after a gap, and calls back on every
/// change with the delta from the previous local version. A late joiner gets the current environment at once
/// (the snapshot topic is transient local).
///
/// Its readers are in the cell's partition only (topics.hpp): other cells' samples never reach it.
/// While in sync it reads only cellmap/environment_delta; it opens a reader on cellmap/environment only while
/// it needs a snapshot (at start and after a gap), so a one-box change costs each planner one small delta on
/// the wire, not a full snapshot.
///
/// A background thread receives and calls `on_change` (never concurrently with itself, never under an
/// internal lock, so the callback may call environment()). The other members are thread-safe.
/// `participant` must outlive the subscriber.
class EnvironmentSubscriber final {
 public:
  using Callback = std::function<void(const Environment& environment, const EnvironmentDelta& delta)>;

  /// @param delta_depth reader history for deltas (KEEP_LAST); deltas beyond it while the callback is busy
  ///        are dropped by DDS and show up as a gap, which resyncs from the snapshot.
  /// @throws Error if a reader cannot be created.
  EnvironmentSubscriber(const dds::Participant& participant, std::string cell, Callback on_change = {},
                        std::uint32_t delta_depth = kDefaultDeltaDepth);
  /// Stops the thread and deletes the readers.
  ~EnvironmentSubscriber();
  EnvironmentSubscriber(const EnvironmentSubscriber&) = delete;
  EnvironmentSubscriber& operator=(const EnvironmentSubscriber&) = delete;

  /// The local copy, or nullopt before the first snapshot arrived.
  [[nodiscard]] std::optional<Environment> environment() const;
  /// Blocks until the local copy reached at least `version` and the callbacks up to it returned, or the
  /// timeout passed; true if it did.
  bool wait_for_version(std::uint64_t version, std::chrono::nanoseconds timeout) const;
  [[nodiscard]] TrackerStats stats() const;
  /// The last problem met by the receiving thread (a malformed sample, a callback that threw), or "".
  [[nodiscard]] std::string last_error() const;

 private:
  void run();
  void receive();
  void open_or_close_snapshot_reader();

  const dds::Participant& participant_;
  Callback on_change_;
  dds::Topic snapshot_topic_;
  dds::Topic delta_topic_;
  dds::Reader delta_reader_;
  std::optional<dds::Reader> snapshot_reader_;  // only while a snapshot is needed; used by the thread only
  dds::WaitSet waitset_;                        // after the readers: its conditions go first

  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  EnvironmentTracker tracker_;           // guarded by mutex_
  std::string last_error_;               // guarded by mutex_
  std::uint64_t delivered_version_ = 0;  // guarded by mutex_: callbacks done up to this version
  bool stop_ = false;                    // guarded by mutex_
  std::thread thread_;
};

}  // namespace cellmap::transport
