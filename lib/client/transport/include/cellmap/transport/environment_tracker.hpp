// SPDX-License-Identifier: Apache-2.0
#pragma once
// The planner side's bookkeeping, free of DDS so it can be tested sample by sample: a local copy of one
// cell's environment kept current from snapshots and deltas arriving in any order.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/environment/environment.hpp"

namespace cellmap::transport {

/// One step of the local copy: the environment after it and the delta from the previous local version (for
/// the first snapshot: from the empty version 0, everything added).
struct EnvironmentUpdate final {
  Environment environment;
  EnvironmentDelta delta;
  bool from_snapshot = false;  ///< true when reached by a snapshot (first copy or resync), not a delta
};

struct TrackerStats final {
  std::uint64_t deltas_applied = 0;
  std::uint64_t snapshots_applied = 0;  ///< the first copy plus every resync
  std::uint64_t gaps = 0;               ///< deltas that did not start at the local version (missed versions)
  std::uint64_t rejected = 0;           ///< deltas that did not fit the local copy (apply() threw)
  std::uint64_t other_cells = 0;        ///< snapshots and deltas of other cells, received and ignored
  std::uint64_t went_back = 0;  ///< times the copy followed a publisher going on below the local version
  std::uint64_t implausible =
      0;  ///< snapshots and deltas refused for jumping more than kMaxVersionJump ahead
};

/// The furthest a snapshot or delta may jump ahead of the local copy: a daemon makes one version per change,
/// so 2³² is more than a cell makes in a century; a version that far ahead is forged (or corrupt), and taking
/// it would leave the copy above everything the daemon publishes after.
inline constexpr std::uint64_t kMaxVersionJump = std::uint64_t{1} << 32;

/// How many samples (snapshots or deltas), each newer than the one before yet older than the local copy, make
/// the copy wait for a snapshot and follow it back: the publisher goes on below what the copy holds (its
/// state was wiped, or the copy took a forged version far ahead), so the local version is not the
/// publisher's.
inline constexpr int kSamplesBelowToFollow = 3;

/// Keeps a local copy of `cell`. Deltas are applied in version order; a delta that does not start at the
/// local version is a gap: it is held, and the copy waits for a snapshot at least as new (needs_snapshot()).
/// A delta from version 0 carries the whole environment (every box added) and counts as a snapshot once a
/// local copy exists (before, the snapshot itself is awaited, so a late joiner jumps straight to the newest).
/// Older or duplicate samples are ignored, unless kSamplesBelowToFollow samples in a row go on below the
/// local version: the copy then needs a snapshot and follows the next one below it (an update from_snapshot
/// whose delta goes from the local version back to it, replacing every box), ignoring meanwhile snapshots at
/// or above the local version (a forger's kept sample). Samples more than kMaxVersionJump ahead of the local
/// copy are refused (counted); the first copy takes any version. Samples of other cells are ignored. Not
/// thread-safe.
class EnvironmentTracker final {
 public:
  explicit EnvironmentTracker(std::string cell);

  /// Feeds one snapshot; returns the updates it caused (none, or the jump to it plus held deltas after it).
  std::vector<EnvironmentUpdate> on_snapshot(const Environment& snapshot);
  /// Feeds one delta; returns the updates it caused (it and any held deltas it connects).
  std::vector<EnvironmentUpdate> on_delta(const EnvironmentDelta& delta);

  /// True while there is no local copy yet or a gap is open: only a snapshot can help.
  [[nodiscard]] bool needs_snapshot() const {
    return !current_ || out_of_sync_ || !held_.empty() || publisher_below();
  }
  [[nodiscard]] const std::optional<Environment>& environment() const { return current_; }
  [[nodiscard]] const TrackerStats& stats() const { return stats_; }
  [[nodiscard]] const std::string& cell() const { return cell_; }

 private:
  void drain(std::vector<EnvironmentUpdate>& updates);
  void note_below(std::uint64_t version);
  [[nodiscard]] bool publisher_below() const { return below_count_ >= kSamplesBelowToFollow; }
  [[nodiscard]] bool implausible(std::uint64_t version) const {
    return current_ && version > current_->version() && version - current_->version() > kMaxVersionJump;
  }

  std::string cell_;
  std::optional<Environment> current_;
  std::map<std::uint64_t, EnvironmentDelta> held_;  // by from_version, all above the local version
  bool out_of_sync_ = false;                        // a delta failed to apply: trust only a snapshot
  std::uint64_t below_version_ = 0;  // the newest of the snapshots in a row below the local version
  int below_count_ = 0;              // how many
  TrackerStats stats_;
};

}  // namespace cellmap::transport
