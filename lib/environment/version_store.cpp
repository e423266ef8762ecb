// SPDX-License-Identifier: Apache-2.0
#include "cellmap/environment/version_store.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::string_view kSnapshotPrefix = "environment-";
constexpr std::string_view kBoxIdPrefix = "next-box-id-";
constexpr std::size_t kDigits = 20;  // fixed width: names sort like numbers

std::string padded(std::uint64_t number) {
  char text[kDigits + 1];
  std::snprintf(text, sizeof text, "%020" PRIu64, number);
  return text;
}

fs::path snapshot_path(const fs::path& dir, std::uint64_t version) {
  return dir / (std::string(kSnapshotPrefix) + padded(version) + ".json");
}
fs::path blob_path(const fs::path& dir, std::uint64_t version) {
  return dir / (std::string(kSnapshotPrefix) + padded(version) + ".blob");
}
fs::path box_id_marker_path(const fs::path& dir, std::uint64_t next_box_id) {
  return dir / (std::string(kBoxIdPrefix) + padded(next_box_id));
}

// A file name of the store split into its number and what follows the digits; nullopt for other files.
struct StateName {
  std::string_view prefix;
  std::uint64_t number = 0;
  std::string suffix;
};
std::optional<StateName> parse_name(const std::string& name) {
  for (const std::string_view prefix : {kSnapshotPrefix, kBoxIdPrefix}) {
    if (name.size() < prefix.size() + kDigits || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size(), kDigits);
    if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) return {};
    std::uint64_t number = 0;
    for (const char c : digits) {
      if (number > (UINT64_MAX - 9) / 10) return {};  // beyond uint64: not a name we wrote
      number = number * 10 + static_cast<std::uint64_t>(c - '0');
    }
    return StateName{prefix, number, name.substr(prefix.size() + kDigits)};
  }
  return {};
}

// An interrupted write_file_atomically leaves ".<name>.XXXXXX"; it was never committed.
bool is_interrupted_write(const std::string& name) {
  return name.rfind("." + std::string(kSnapshotPrefix), 0) == 0 ||
         name.rfind("." + std::string(kBoxIdPrefix), 0) == 0;
}

// FNV-1a, 64 bit: a few lines, stable across compilers and runs (std::hash is neither), and enough to catch
// a truncated or bit-rotted blob; it is not meant to resist tampering.
std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t hash = 14695981039346656037ull;
  for (const unsigned char c : bytes) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return hash;
}

void remove_quietly(const fs::path& path) {
  std::error_code ec;
  fs::remove(path, ec);
}

std::uint64_t above_ids(const std::vector<Box>& boxes) {
  std::uint64_t next = 1;
  for (const Box& box : boxes) next = std::max(next, box.id + 1);
  return next;
}

struct LoadedSnapshot {
  Environment environment;
  std::optional<fs::path> blob;
  std::optional<std::uint64_t> next_box_id;  // absent in snapshots of older versions
};

// The blob's entry of a snapshot: the path of the blob if it is intact, nothing if none was saved.
// @throws Error with the reason when the entry is malformed or the blob does not match it.
std::optional<fs::path> check_blob(const json& doc, const fs::path& dir, std::uint64_t version) {
  const fs::path path = snapshot_path(dir, version);
  const auto blob = doc.find("blob");
  if (blob == doc.end()) throw Error(path.string() + ": blob: missing");
  if (blob->is_null()) return std::nullopt;
  const auto size = blob->find("size");
  const auto hash = blob->find("fnv1a64");
  if (!blob->is_object() || size == blob->end() || hash == blob->end() || !size->is_number_unsigned() ||
      !hash->is_number_unsigned()) {
    throw Error(path.string() + ": blob: must be null or {\"size\", \"fnv1a64\"}");
  }
  const fs::path data_path = blob_path(dir, version);
  const std::string data = read_file(data_path);
  if (data.size() != size->get<std::uint64_t>()) {
    throw Error(data_path.string() + ": truncated: " + std::to_string(data.size()) + " bytes, expected " +
                std::to_string(size->get<std::uint64_t>()));
  }
  if (fnv1a64(data) != hash->get<std::uint64_t>()) throw Error(data_path.string() + ": checksum mismatch");
  return data_path;
}

// Reads and checks one snapshot (and its blob). @throws Error with the reason when anything is off.
LoadedSnapshot load_snapshot(const fs::path& dir, std::uint64_t version) {
  const fs::path path = snapshot_path(dir, version);
  const std::string text = read_file(path);
  const BoxSet set = box_set_from_json(text, path.string());
  const json doc = json::parse(text);  // valid: box_set_from_json parsed it
  if (set.version != version) {
    throw Error(path.string() + ": version: " + std::to_string(set.version) +
                " does not match the file name");
  }
  const auto stored_cell = doc.find("cell");
  if (stored_cell == doc.end() || !stored_cell->is_string()) throw Error(path.string() + ": cell: missing");
  const auto stamp = doc.find("stamp_ns");
  if (stamp == doc.end() || !stamp->is_number_integer()) throw Error(path.string() + ": stamp_ns: missing");
  LoadedSnapshot loaded{
      Environment(stored_cell->get<std::string>(), version, stamp->get<std::int64_t>(), set.boxes),
      check_blob(doc, dir, version), std::nullopt};
  const auto next_box_id = doc.find("next_box_id");
  if (next_box_id != doc.end()) {
    if (!next_box_id->is_number_unsigned()) throw Error(path.string() + ": next_box_id: not a box id");
    loaded.next_box_id = next_box_id->get<std::uint64_t>();
  }
  return loaded;
}

}  // namespace

// The store's files found when it opened.
struct VersionStore::Listing {
  std::map<std::uint64_t, std::vector<fs::path>> files;  // version -> its live (not .corrupt) files
  std::vector<std::uint64_t> snapshots;                  // versions that have a snapshot JSON
  std::vector<fs::path> box_id_markers;
};

VersionStore::VersionStore(fs::path state_dir, std::string cell)
    : dir_(std::move(state_dir)),
      cell_(std::move(cell)),
      recovered_{Environment(cell_), std::nullopt, 1, {}} {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw Error(dir_.string() + ": cannot create state directory: " + ec.message());
  // The environment goes encrypted over DDS under Security: no other local user reads it here either.
  fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::replace, ec);
  if (ec) throw Error(dir_.string() + ": cannot make the state directory its owner's only: " + ec.message());
  Listing listing = list_directory();
  load_newest_intact(listing);
  remove_superseded(listing);
}

std::optional<std::string> VersionStore::stored_cell(const fs::path& state_dir) {
  std::vector<std::uint64_t> snapshots;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(state_dir, ec)) {
    const std::optional<StateName> parsed = parse_name(entry.path().filename().string());
    if (parsed && parsed->prefix == kSnapshotPrefix && parsed->suffix == ".json")
      snapshots.push_back(parsed->number);
  }
  std::sort(snapshots.rbegin(), snapshots.rend());
  for (const std::uint64_t version : snapshots) {
    try {
      return load_snapshot(state_dir, version).environment.cell();
    } catch (const Error&) {
      // A corrupt snapshot says nothing about the cell; the store skips it too.
    }
  }
  return std::nullopt;
}

VersionStore::Listing VersionStore::list_directory() {
  Listing listing;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (is_interrupted_write(name)) {
      remove_quietly(entry.path());
      continue;
    }
    const std::optional<StateName> parsed = parse_name(name);
    if (!parsed) continue;
    if (parsed->prefix == kBoxIdPrefix) {
      if (!parsed->suffix.empty()) continue;
      box_id_marker_ = std::max(box_id_marker_, parsed->number);
      listing.box_id_markers.push_back(entry.path());
      continue;
    }
    // Every number a file names counts as used, corrupt files included: it may have been published.
    highest_used_ = std::max(highest_used_, parsed->number);
    if (parsed->suffix == ".json" || parsed->suffix == ".blob") {
      listing.files[parsed->number].push_back(entry.path());
      if (parsed->suffix == ".json") listing.snapshots.push_back(parsed->number);
    }
  }
  if (ec) throw Error(dir_.string() + ": cannot list state directory: " + ec.message());
  return listing;
}

// Newest first: the first intact snapshot is loaded, the second intact one is kept as the previous good.
void VersionStore::load_newest_intact(Listing& listing) {
  std::sort(listing.snapshots.rbegin(), listing.snapshots.rend());
  std::optional<std::uint64_t> stored_next_box_id;
  for (const std::uint64_t version : listing.snapshots) {
    if (good_.size() == 2) break;
    std::optional<LoadedSnapshot> loaded;
    try {
      loaded = load_snapshot(dir_, version);
    } catch (const Error& e) {
      recovered_.problems.push_back(std::string(e.what()) + " (skipped, renamed to *.corrupt)");
      std::error_code ec;
      for (const fs::path& path : {snapshot_path(dir_, version), blob_path(dir_, version)}) {
        if (fs::exists(path, ec)) fs::rename(path, path.string() + ".corrupt", ec);
      }
      listing.files.erase(version);
      continue;
    }
    // Another cell's state is a wrong directory, not corruption: refuse rather than overwrite it.
    if (loaded->environment.cell() != cell_) {
      throw Error(snapshot_path(dir_, version).string() + ": holds cell '" + loaded->environment.cell() +
                  "', not '" + cell_ + "'");
    }
    if (good_.empty()) {
      recovered_.environment = std::move(loaded->environment);
      recovered_.blob = loaded->blob;
      stored_next_box_id = loaded->next_box_id;
    }
    good_.insert(good_.begin(), version);
  }
  last_saved_ = good_.empty() ? 0 : good_.back();
  if (last_saved_ != 0 && !stored_next_box_id) {
    recovered_.problems.push_back(snapshot_path(dir_, last_saved_).string() +
                                  ": no next_box_id (written by an older version): box ids go on above "
                                  "the ids it holds");
  }
  // The marker reserves ids ahead of the counter, so it is the counter only once a newer version may have
  // gone out (its snapshot lost) or the snapshot does not say.
  const bool newest_lost = last_saved_ < highest_used_ || !stored_next_box_id;
  next_box_id_ = std::max({newest_lost ? box_id_marker_ : 0, stored_next_box_id.value_or(1),
                           above_ids(recovered_.environment.boxes())});
  recovered_.next_box_id = next_box_id_;
}

// Anything else is superseded: versions older than the previous good one, blobs whose snapshot was never
// committed, box-id markers below the highest.
void VersionStore::remove_superseded(const Listing& listing) const {
  for (const auto& [version, paths] : listing.files) {
    if (std::find(good_.begin(), good_.end(), version) != good_.end()) continue;
    for (const fs::path& path : paths) remove_quietly(path);
  }
  for (const fs::path& marker : listing.box_id_markers) {
    if (marker != box_id_marker_path(dir_, box_id_marker_)) remove_quietly(marker);
  }
}

Environment VersionStore::resume(std::int64_t stamp_ns, std::optional<std::string_view> blob) {
  const Environment& recovered = recovered_.environment;
  if (recovered.version() == 0 || next_version() == recovered.version() + 1) return recovered;
  Environment again(cell_, next_version(), stamp_ns, recovered.boxes());
  save(again, blob, next_box_id_);
  return again;
}

void VersionStore::save(const Environment& env, std::optional<std::string_view> blob,
                        std::uint64_t next_box_id) {
  const std::string what = dir_.string() + ": save version " + std::to_string(env.version());
  if (env.cell() != cell_)
    throw Error(what + ": cell '" + env.cell() + "' is not the store's '" + cell_ + "'");
  if (env.version() <= last_saved_) {
    throw Error(what + ": not above the last saved version " + std::to_string(last_saved_));
  }
  const std::uint64_t counter = std::max({next_box_id, next_box_id_, above_ids(env.boxes())});
  if (!holds_last_saved()) box_id_marker_ = 0;  // the directory was emptied: write the marker anew
  raise_box_id_marker(counter);
  json doc = json::parse(to_json(BoxSet{env.version(), "cell", env.boxes()}));
  doc["cell"] = env.cell();
  doc["stamp_ns"] = env.stamp_ns();
  doc["next_box_id"] = counter;
  doc["blob"] = nullptr;
  if (blob) {
    write_file_atomically(blob_path(dir_, env.version()), *blob);
    doc["blob"] = {{"size", blob->size()}, {"fnv1a64", fnv1a64(*blob)}};
  }
  // The snapshot is the commit point: a crash before this rename leaves the previous version loadable.
  write_file_atomically(snapshot_path(dir_, env.version()), doc.dump(1) + "\n");
  last_snapshot_ = blob ? std::string() : doc.dump();
  last_saved_ = env.version();
  highest_used_ = std::max(highest_used_, env.version());
  next_box_id_ = counter;
  good_.push_back(env.version());
  while (good_.size() > 2) {
    remove_quietly(snapshot_path(dir_, good_.front()));
    remove_quietly(blob_path(dir_, good_.front()));
    good_.erase(good_.begin());
  }
}

void VersionStore::attach_blob(std::uint64_t version, std::string_view blob) {
  const std::string what = dir_.string() + ": attach a blob to version " + std::to_string(version);
  if (version != last_saved_ || last_snapshot_.empty())
    throw Error(what + ": not the newest version saved without a blob");
  json doc = json::parse(last_snapshot_);
  write_file_atomically(blob_path(dir_, version), blob);
  doc["blob"] = {{"size", blob.size()}, {"fnv1a64", fnv1a64(blob)}};
  write_file_atomically(snapshot_path(dir_, version), doc.dump(1) + "\n");
  last_snapshot_.clear();
}

// The marker goes out before the snapshot that uses the ids, so no crash leaves a published id above it. It
// reserves kBoxIdsReserved ids ahead, so most versions that hand out ids cost one fsynced write, not two.
void VersionStore::raise_box_id_marker(std::uint64_t next_box_id) {
  if (next_box_id <= box_id_marker_) return;
  const std::uint64_t reserved = next_box_id + kBoxIdsReserved;
  write_file_atomically(box_id_marker_path(dir_, reserved), "");
  if (box_id_marker_ != 0) remove_quietly(box_id_marker_path(dir_, box_id_marker_));
  box_id_marker_ = reserved;
}

bool VersionStore::holds_last_saved() const {
  if (last_saved_ == 0) return true;
  std::error_code ec;
  return fs::exists(snapshot_path(dir_, last_saved_), ec);
}

}  // namespace cellmap
