// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmap/sim/scene_edits: how `cellmap inject` edits the simulated scene of a running daemon.

#include <chrono>
#include <vector>

#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/input_limits.hpp"
#include "cellmap/transport/messages.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::transport {

/// Sends scene edits. The topic is volatile (a restarted daemon must not replay old edits), so a short-lived
/// sender waits for the daemon's reader before writing and for its acknowledgement before exiting.
/// `participant` must outlive it.
class SceneEditWriter final {
 public:
  /// Writes into the partition of `cell`, reaching that cell's daemon; with kEveryCell every simulating
  /// daemon on the domain (its edits have an empty cell).
  SceneEditWriter(const dds::Participant& participant, std::string cell);
  /// True once at least one scene-edit reader (a simulating daemon) matched, false on timeout.
  bool wait_for_reader(std::chrono::nanoseconds timeout) const;
  /// @throws Error if the edit has no name, is for another cell than the writer (an empty cell on a
  /// kEveryCell writer), or the write fails.
  void write(const SceneEdit& edit) const;
  /// True once every matched reader acknowledged everything written, false on timeout.
  bool wait_for_acks(std::chrono::nanoseconds timeout) const;

 private:
  std::string cell_;
  dds::Topic topic_;
  dds::Writer writer_;
};

/// Receives scene edits (the simulator side). `participant` must outlive it. Not thread-safe.
class SceneEditReader final {
 public:
  /// @param cell       reads the partition of this cell (edits for it and for every cell)
  /// @param limits     edits outside them are refused (input_limits.hpp)
  /// @param on_refused called with the reason of each refused edit, from take()
  SceneEditReader(const dds::Participant& participant, const std::string& cell, InputLimits limits = {},
                  OnRefused on_refused = {});
  ~SceneEditReader();
  SceneEditReader(const SceneEditReader&) = delete;
  SceneEditReader& operator=(const SceneEditReader&) = delete;
  /// Waits up to `timeout` (zero: just looks) and returns the edits received, oldest first. Malformed edits
  /// and edits outside the limits are refused: skipped, counted in rejected() and passed to on_refused.
  std::vector<SceneEdit> take(std::chrono::nanoseconds timeout = std::chrono::nanoseconds(0));
  [[nodiscard]] std::uint64_t rejected() const { return rejected_; }

 private:
  InputLimits limits_;
  OnRefused on_refused_;
  dds::Topic topic_;
  dds::Reader reader_;
  dds::WaitSet waitset_;
  std::uint64_t rejected_ = 0;
};

}  // namespace cellmap::transport
