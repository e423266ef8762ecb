// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmapd's versions: the pipeline recovered from the state directory, and each version of its boxes
// numbered, stamped, saved and only then published, retried until it is out.

#include <cstdint>
#include <functional>
#include <string>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "cellmap/environment/environment.hpp"
#include "cellmap/environment/version_store.hpp"

namespace cellmap::daemon {

/// The cell pipeline as the state directory left it: the recovered boxes, the store's box-id counter and the
/// saved map. A map state that is missing or unreadable is logged and the map starts empty (it settles
/// again); box ids still go on above every id the cell ever handed out.
[[nodiscard]] CellPipeline recover_pipeline(const CellPipelineConfig& config,
                                            const RecoveredState& recovered);

/// Nanoseconds since the Unix epoch.
using WallClock = std::function<std::int64_t()>;

/// Gets every version of the cell out, in the order that keeps a number seen by subscribers on disk:
/// numbers it (VersionStore::next_version()), stamps it (the wall clock, but always above the previous stamp:
/// a clock stepped back does not make stamps go backwards), saves its boxes and the box-id counter, only then
/// publishes it with its delta from what subscribers have, and then saves the map state with it (a few MB
/// that subscribers need not wait for). A crash before the map state is on disk restarts with the version's
/// boxes and an empty map, which settles again.
///
/// Nothing is dropped on a fault: a save or a publication that fails (disk full, state directory removed or
/// read-only, a DDS write refused) is logged once with the reason, fault() says why, subscribers keep the
/// last version that went out, and every flush() tries again with the boxes current then; the version goes
/// out as soon as a save and a publication succeed. A state directory removed under the daemon is noticed
/// and the current boxes are saved again (as a new version), so a restart never misses what went out.
///
/// Not thread-safe: the processing thread owns it. `store` must outlive it.
class VersionKeeper final {
 public:
  /// Hands a saved version to subscribers: `delta` leads from the last version published (version 0 before
  /// the first) to `env`. @throws Error when the write fails.
  using Publish = std::function<void(const Environment& env, const EnvironmentDelta& delta)>;

  VersionKeeper(VersionStore& store, Publish publish, WallClock clock = wall_clock_ns);

  /// At start: announces what the state directory holds, under the number VersionStore::resume() gives
  /// (saved again with `pipeline`'s map state when a newer number may have been lost). Faults as in flush().
  void resume(const CellPipeline& pipeline);
  /// After each sweep (and now and then while pending()): publish_boxes(), then save_map_state().
  void flush(const CellPipeline& pipeline);
  /// Saves a version of the pipeline's boxes if they differ from the newest saved version, if an earlier
  /// save failed or if the saved state vanished; then publishes the newest saved version if subscribers do
  /// not have it yet. Never throws for I/O or DDS faults.
  void publish_boxes(const CellPipeline& pipeline);
  /// Saves the pipeline's map state with the newest saved version if it has none yet. Never throws for I/O
  /// faults (retried by the next call).
  void save_map_state(const CellPipeline& pipeline);

  /// Whether a save or a publication failed and waits for the next flush().
  [[nodiscard]] bool pending() const {
    return save_owed_ || map_state_owed_ || saved_.version() > published_.version();
  }
  /// Why the newest content is not out yet (one line); empty when everything went out.
  [[nodiscard]] const std::string& fault() const { return fault_; }
  /// What subscribers have: the last version published (version 0 before the first).
  [[nodiscard]] const Environment& published() const { return published_; }

 private:
  [[nodiscard]] bool save_due(const std::vector<Box>& boxes);
  void save(const CellPipeline& pipeline);
  void publish_saved();
  void failed(const std::string& reason);
  // Logs that everything went out after faults, and clears them.
  void recovered();
  [[nodiscard]] std::int64_t next_stamp() const;

  VersionStore& store_;
  Publish publish_;
  WallClock clock_;
  Environment saved_;            // the newest version on disk (the recovered one at start)
  Environment published_;        // the newest version published
  bool save_owed_ = false;       // a save failed: one is due whatever the boxes
  bool map_state_owed_ = false;  // the newest saved version has no map state yet
  bool resumed_ = false;         // saved_ is what the state directory held, not yet announced
  std::string fault_;
  std::uint64_t failed_attempts_ = 0;  // since the last success
};

}  // namespace cellmap::daemon
