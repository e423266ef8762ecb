// SPDX-License-Identifier: Apache-2.0
#pragma once
// Crash-safe persistence of a cell's environment versions in a state directory.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cellmap/environment/environment.hpp"

namespace cellmap {

/// What VersionStore found in its state directory when it opened.
struct RecoveredState final {
  /// The newest snapshot that read back intact, or the empty environment (version 0) of a fresh directory.
  Environment environment;
  /// The opaque blob saved with that snapshot (the daemon's map state), if one was saved.
  std::optional<std::filesystem::path> blob;
  /// Above every box id the cell ever handed out, as far as the directory tells (>= 1): the snapshot's
  /// `next_box_id` and its boxes' ids + 1, and the `next-box-id-<n>` marker when a newer version may have
  /// gone out (its snapshot was corrupt) or the snapshot has no `next_box_id`. Corrupt snapshots or a lost
  /// blob do not lower it; the ids then jump by at most VersionStore::kBoxIdsReserved.
  std::uint64_t next_box_id = 1;
  /// One line per state file that was corrupt, truncated or unreadable and was skipped (then renamed to
  /// `<name>.corrupt` so an operator can inspect it), and one per snapshot in an older format. Empty when
  /// everything read back.
  std::vector<std::string> problems;
};

/// Persists environment versions of one cell in `state_dir` so that after a crash at any instant (SIGKILL
/// mid-write included) the newest intact version is loaded, and neither version numbers nor box ids are ever
/// reused.
///
/// Files: `environment-<version>.json` (the boxes JSON plus "cell", "stamp_ns", "next_box_id" and the blob's
/// size/checksum), `environment-<version>.blob` (opaque, optional) and `next-box-id-<n>` (an empty marker
/// whose name is above every box id handed out so far, by up to kBoxIdsReserved; a name survives what
/// corrupts a file's content). Every
/// file is written with write_file_atomically; the snapshot JSON is written last and is the commit point of
/// a version. The newest two intact versions are kept (the current one and the previous good one); older
/// ones are deleted.
///
/// Publishing rule for the caller, so that a number seen by subscribers is never given to other content:
/// save(v) before publishing v (its blob may follow, attach_blob). next_version() is above every version any
/// file names (corrupt ones too).
/// After a restart, announce resume()'s environment first.
///
/// Not thread-safe; one VersionStore per state directory (no inter-process locking).
class VersionStore final {
 public:
  /// Opens `state_dir` (created if missing, and made readable by its owner only: mode 0700), removes
  /// temporary files of interrupted writes and loads the newest intact snapshot (see recovered()).
  /// @throws Error if the directory cannot be created, restricted or listed, or holds a snapshot of another
  /// cell.
  VersionStore(std::filesystem::path state_dir, std::string cell);

  /// The cell whose versions `state_dir` holds: the one the newest snapshot that reads back names. Read
  /// without changing anything (a check before a start, `cellmapd --check`); nullopt if the directory holds
  /// no snapshot that reads back, or does not exist. The constructor refuses another cell's directory.
  [[nodiscard]] static std::optional<std::string> stored_cell(const std::filesystem::path& state_dir);

  /// What was loaded when the store opened.
  [[nodiscard]] const RecoveredState& recovered() const { return recovered_; }

  /// The smallest version number never saved in this directory nor named by any of its files (>= 1).
  [[nodiscard]] std::uint64_t next_version() const { return highest_used_ + 1; }
  /// Above every box id handed out so far: recovered().next_box_id, raised by each save().
  [[nodiscard]] std::uint64_t next_box_id() const { return next_box_id_; }
  /// How far the marker reaches above the counter when a save raises it: only a save whose ids pass it
  /// writes a new marker, and a lost newest snapshot makes the ids jump by at most this much.
  static constexpr std::uint64_t kBoxIdsReserved = 1024;

  /// The restart rule, in one place: the environment to announce first after opening. That is the recovered
  /// one, unless a number above it may have gone out (next_version() > its version + 1: a newer snapshot was
  /// corrupt or its blob lost); then its boxes are saved again under next_version() with `stamp_ns` and
  /// `blob`, so subscribers that saw the lost number move forward. Version 0 (nothing recovered) comes back
  /// as it is: nothing to announce.
  /// @throws Error as save(); the store is then unchanged and resume() can be called again.
  [[nodiscard]] Environment resume(std::int64_t stamp_ns,
                                   std::optional<std::string_view> blob = std::nullopt);

  /// Durably stores `env` (and `blob`, if given) as the newest version, then deletes versions older than the
  /// previous good one. `next_box_id` is the caller's id counter (0: none); the store keeps the highest of
  /// it, env's ids + 1 and what it held, marker first, so after any crash next_box_id() is above every id of
  /// every version that was saved.
  /// @throws Error if env.cell() is not this store's cell or env.version() is not above the last saved
  /// version, or on I/O failure (the previous state is then untouched and the same version can be saved
  /// again).
  void save(const Environment& env, std::optional<std::string_view> blob = std::nullopt,
            std::uint64_t next_box_id = 0);
  /// Adds `blob` to the newest saved version, saved without one: the blob is written, then the snapshot
  /// again with the blob's size and checksum, so a caller can publish a version once its boxes are on disk
  /// and save the larger blob after. A crash before the snapshot's rename leaves the version as it was
  /// (boxes, no blob), never one that does not read back.
  /// @throws Error if `version` is not the newest saved version or already has a blob, or on I/O failure
  /// (the version is then unchanged and attach_blob can be called again).
  void attach_blob(std::uint64_t version, std::string_view blob);

  /// False once the newest saved version's snapshot is no longer on disk (the state directory was removed or
  /// emptied by hand): a restart would not find it, so the caller should save its environment again. True
  /// before anything was saved. One stat() call.
  [[nodiscard]] bool holds_last_saved() const;

  [[nodiscard]] const std::filesystem::path& directory() const { return dir_; }

 private:
  struct Listing;
  [[nodiscard]] Listing list_directory();
  void load_newest_intact(Listing& listing);
  void remove_superseded(const Listing& listing) const;
  void raise_box_id_marker(std::uint64_t next_box_id);

  std::filesystem::path dir_;
  std::string cell_;
  RecoveredState recovered_;
  std::uint64_t highest_used_ = 0;  // max version saved or named by any file (corrupt included)
  std::uint64_t last_saved_ = 0;    // version of the newest intact snapshot
  std::string last_snapshot_;       // its JSON as written by save() (for attach_blob); empty = not known
  std::uint64_t next_box_id_ = 1;
  std::uint64_t box_id_marker_ = 0;  // the n of the newest next-box-id-<n> on disk, 0 = none
  std::vector<std::uint64_t> good_;  // intact versions, oldest first; the last two are kept on disk
};

}  // namespace cellmap
