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
  /// The opaque blob saved with that snapshot (the daemon's OcTree .bt), if one was saved.
  std::optional<std::filesystem::path> blob;
  /// One line per state file that was corrupt, truncated or unreadable and was skipped (then renamed to
  /// `<name>.corrupt` so an operator can inspect it). Empty when everything read back.
  std::vector<std::string> problems;
};

/// Persists environment versions of one cell in `state_dir` so that after a crash at any instant (SIGKILL
/// mid-write included) the newest intact version is loaded and version numbers are never reused.
///
/// Files: `environment-<version>.json` (the boxes JSON of ARCHITECTURE.md plus "cell", "stamp_ns" and the
/// blob's size/checksum), `environment-<version>.blob` (opaque, optional) and `reserved-<version>` (an empty
/// marker whose name is the highest version that may have been published). Every file is written with
/// write_file_atomically; the snapshot JSON is written last and is the commit point of a version. The newest
/// two intact versions are kept (the current one and the previous good one); older ones are deleted.
///
/// Publishing rule for the caller, so that a number seen by subscribers is never given to other content:
/// either save(v) before publishing v, or reserve(v) before publishing and save(v) after. After a crash
/// next_version() is above every version that was saved or reserved.
///
/// On restart: if next_version() > recovered().environment.version() + 1, a reserved number may have gone
/// out unsaved; save the recovered boxes again under next_version() before republishing them, so subscribers
/// that saw the lost version move forward (tests/transport/publisher_helper.cpp does exactly this).
///
/// Not thread-safe; one VersionStore per state directory (no inter-process locking).
class VersionStore final {
 public:
  /// Opens `state_dir` (created if missing), removes temporary files of interrupted writes and loads the
  /// newest intact snapshot (see recovered()).
  /// @throws Error if the directory cannot be created or listed, or holds a snapshot of another cell.
  VersionStore(std::filesystem::path state_dir, std::string cell);

  /// What was loaded when the store opened.
  [[nodiscard]] const RecoveredState& recovered() const { return recovered_; }

  /// The smallest version number never saved nor reserved in this directory (>= 1).
  [[nodiscard]] std::uint64_t next_version() const { return highest_used_ + 1; }

  /// Durably records that `version` may be published; returns once the marker is on disk (a file create and
  /// two fsyncs, cheaper than save() with a large blob).
  /// @throws Error if version < next_version() - 1 (reserving backwards) or on I/O failure.
  void reserve(std::uint64_t version);

  /// Durably stores `env` (and `blob`, if given) as the newest version, then deletes versions older than the
  /// previous good one.
  /// @throws Error if env.cell() is not this store's cell, env.version() is not above the last saved version
  /// or is below the highest reserved one, or on I/O failure (the previous state is then untouched).
  void save(const Environment& env, std::optional<std::string_view> blob = std::nullopt);

  [[nodiscard]] const std::filesystem::path& directory() const { return dir_; }

 private:
  std::filesystem::path dir_;
  std::string cell_;
  RecoveredState recovered_;
  std::uint64_t highest_used_ = 0;  // max version saved, reserved, or named by any file (corrupt included)
  std::uint64_t highest_reserved_ = 0;  // max version named by a reserved-<v> marker
  std::uint64_t last_saved_ = 0;        // version of the newest intact snapshot
  std::vector<std::uint64_t> good_;     // intact versions, oldest first; the last two are kept on disk
};

}  // namespace cellmap
