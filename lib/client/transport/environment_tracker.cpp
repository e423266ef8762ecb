// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/environment_tracker.hpp"

#include "cellmap/common/error.hpp"

namespace cellmap::transport {
namespace {

// Deltas held across a gap are few (the writer keeps at most its history depth); cap them anyway so a
// publisher that never sends a snapshot cannot grow this without bound.
constexpr std::size_t kMaxHeld = 256;

}  // namespace

EnvironmentTracker::EnvironmentTracker(std::string cell) : cell_(std::move(cell)) {}

std::vector<EnvironmentUpdate> EnvironmentTracker::on_snapshot(const Environment& snapshot) {
  std::vector<EnvironmentUpdate> updates;
  if (snapshot.cell() != cell_) {
    ++stats_.other_cells;
    return updates;
  }
  if (implausible(snapshot.version())) {
    ++stats_.implausible;
    return updates;
  }
  const bool went_back = current_ && snapshot.version() < current_->version();
  if (went_back) {
    note_below(snapshot.version());
    if (!publisher_below()) return updates;
  } else if (publisher_below()) {
    return updates;  // following the publisher back: only a snapshot below the copy is its
  } else if (current_ && snapshot.version() == current_->version() && !out_of_sync_) {
    below_count_ = 0;  // the publisher is where the copy is
    return updates;
  }
  below_count_ = 0;
  EnvironmentDelta delta;
  if (went_back) {
    // Every box replaced: the local copy's boxes are not the publisher's.
    delta = diff(Environment(cell_, 0, 0, current_->boxes()), snapshot);
    delta.from_version = current_->version();
    held_.clear();
    ++stats_.went_back;
  } else {
    const Environment before =
        current_ && current_->version() < snapshot.version() ? *current_ : Environment(cell_);
    delta = diff(before, snapshot);
  }
  current_ = snapshot;
  out_of_sync_ = false;
  ++stats_.snapshots_applied;
  updates.push_back({snapshot, std::move(delta), true});
  drain(updates);
  return updates;
}

void EnvironmentTracker::note_below(std::uint64_t version) {
  if (below_count_ > 0 && version <= below_version_) return;  // a stale duplicate
  below_version_ = version;
  ++below_count_;
}

std::vector<EnvironmentUpdate> EnvironmentTracker::on_delta(const EnvironmentDelta& delta) {
  std::vector<EnvironmentUpdate> updates;
  if (delta.cell != cell_) {
    ++stats_.other_cells;
    return updates;
  }
  if (delta.to_version <= delta.from_version) return updates;
  if (implausible(delta.to_version)) {
    ++stats_.implausible;
    return updates;
  }
  if (delta.from_version == 0 && current_) {
    // From nothing: the whole environment (a restarted publisher's first version). Without a local copy yet
    // it is held like any delta: the snapshot topic brings the current version, not a replay of history.
    try {
      return on_snapshot(Environment(delta.cell, delta.to_version, delta.stamp_ns, delta.added));
    } catch (const Error&) {
      ++stats_.rejected;  // repeated box ids
      return updates;
    }
  }
  if (current_ && delta.to_version <= current_->version()) {
    if (delta.to_version < current_->version()) note_below(delta.to_version);
    return updates;
  }
  below_count_ = 0;
  if (current_ && delta.from_version != current_->version()) ++stats_.gaps;
  held_[delta.from_version] = delta;
  while (held_.size() > kMaxHeld) held_.erase(held_.begin());
  drain(updates);
  return updates;
}

void EnvironmentTracker::drain(std::vector<EnvironmentUpdate>& updates) {
  if (!current_) return;
  // Drop what the local copy already passed, then apply while the next delta starts where we are.
  while (!held_.empty() && held_.begin()->second.to_version <= current_->version())
    held_.erase(held_.begin());
  while (!out_of_sync_) {
    const auto next = held_.find(current_->version());
    if (next == held_.end()) break;
    EnvironmentDelta delta = std::move(next->second);
    held_.erase(next);
    try {
      current_ = apply(*current_, delta);
    } catch (const Error&) {
      // The delta contradicts the local copy (e.g. adds an id we already have): only a snapshot can tell.
      ++stats_.rejected;
      out_of_sync_ = true;
      break;
    }
    ++stats_.deltas_applied;
    updates.push_back({*current_, std::move(delta), false});
    while (!held_.empty() && held_.begin()->second.to_version <= current_->version())
      held_.erase(held_.begin());
  }
}

}  // namespace cellmap::transport
