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
constexpr std::string_view kReservedPrefix = "reserved-";
constexpr std::size_t kDigits = 20;  // fixed width: names sort like versions

std::string padded(std::uint64_t version) {
  char text[kDigits + 1];
  std::snprintf(text, sizeof text, "%020" PRIu64, version);
  return text;
}

fs::path snapshot_path(const fs::path& dir, std::uint64_t version) {
  return dir / (std::string(kSnapshotPrefix) + padded(version) + ".json");
}
fs::path blob_path(const fs::path& dir, std::uint64_t version) {
  return dir / (std::string(kSnapshotPrefix) + padded(version) + ".blob");
}
fs::path reserved_path(const fs::path& dir, std::uint64_t version) {
  return dir / (std::string(kReservedPrefix) + padded(version));
}

// A file name of the store split into its version and what follows the digits; nullopt for other files.
struct StateName {
  std::string_view prefix;
  std::uint64_t version = 0;
  std::string suffix;
};
std::optional<StateName> parse_name(const std::string& name) {
  for (const std::string_view prefix : {kSnapshotPrefix, kReservedPrefix}) {
    if (name.size() < prefix.size() + kDigits || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size(), kDigits);
    if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) return {};
    std::uint64_t version = 0;
    for (const char c : digits) {
      if (version > (UINT64_MAX - 9) / 10) return {};  // beyond uint64: not a name we wrote
      version = version * 10 + static_cast<std::uint64_t>(c - '0');
    }
    return StateName{prefix, version, name.substr(prefix.size() + kDigits)};
  }
  return {};
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

struct LoadedSnapshot {
  Environment environment;
  std::optional<fs::path> blob;
};

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
      std::nullopt};
  const auto blob = doc.find("blob");
  if (blob == doc.end()) throw Error(path.string() + ": blob: missing");
  if (!blob->is_null()) {
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
    loaded.blob = data_path;
  }
  return loaded;
}

}  // namespace

VersionStore::VersionStore(fs::path state_dir, std::string cell)
    : dir_(std::move(state_dir)), cell_(std::move(cell)), recovered_{Environment(cell_), std::nullopt, {}} {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw Error(dir_.string() + ": cannot create state directory: " + ec.message());

  std::map<std::uint64_t, std::vector<fs::path>> files;  // version -> its live (not .corrupt) files
  std::vector<std::uint64_t> snapshots;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    // An interrupted write_file_atomically leaves ".<name>.XXXXXX"; it was never committed.
    if (name.rfind("." + std::string(kSnapshotPrefix), 0) == 0 ||
        name.rfind("." + std::string(kReservedPrefix), 0) == 0) {
      remove_quietly(entry.path());
      continue;
    }
    const std::optional<StateName> parsed = parse_name(name);
    if (!parsed) continue;
    // Every number a file names counts as used, corrupt files included: it may have been published.
    highest_used_ = std::max(highest_used_, parsed->version);
    if (parsed->prefix == kReservedPrefix) {
      highest_reserved_ = std::max(highest_reserved_, parsed->version);
      files[parsed->version].push_back(entry.path());
    } else if (parsed->suffix == ".json" || parsed->suffix == ".blob") {
      files[parsed->version].push_back(entry.path());
      if (parsed->suffix == ".json") snapshots.push_back(parsed->version);
    }
  }
  if (ec) throw Error(dir_.string() + ": cannot list state directory: " + ec.message());

  // Newest first: the first intact snapshot is loaded, the second intact one is kept as the previous good.
  std::sort(snapshots.rbegin(), snapshots.rend());
  for (const std::uint64_t version : snapshots) {
    if (good_.size() == 2) break;
    std::optional<LoadedSnapshot> loaded;
    try {
      loaded = load_snapshot(dir_, version);
    } catch (const Error& e) {
      recovered_.problems.push_back(std::string(e.what()) + " (skipped, renamed to *.corrupt)");
      for (const fs::path& path : {snapshot_path(dir_, version), blob_path(dir_, version)}) {
        if (fs::exists(path, ec)) fs::rename(path, path.string() + ".corrupt", ec);
      }
      files.erase(version);
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
    }
    good_.insert(good_.begin(), version);
  }
  last_saved_ = good_.empty() ? 0 : good_.back();

  // Anything else is superseded: versions older than the previous good one, blobs whose snapshot was never
  // committed, reservation markers below the highest.
  for (const auto& [version, paths] : files) {
    const bool keep_snapshot = std::find(good_.begin(), good_.end(), version) != good_.end();
    for (const fs::path& path : paths) {
      const bool reserved = parse_name(path.filename().string())->prefix == kReservedPrefix;
      if (reserved ? version < highest_reserved_ : !keep_snapshot) remove_quietly(path);
    }
  }
}

void VersionStore::reserve(std::uint64_t version) {
  if (version < highest_used_) {
    throw Error(dir_.string() + ": reserve: version " + std::to_string(version) +
                " is below the highest used " + std::to_string(highest_used_));
  }
  write_file_atomically(reserved_path(dir_, version), "");
  if (highest_reserved_ != 0 && highest_reserved_ != version)
    remove_quietly(reserved_path(dir_, highest_reserved_));
  highest_reserved_ = version;
  highest_used_ = std::max(highest_used_, version);
}

void VersionStore::save(const Environment& env, std::optional<std::string_view> blob) {
  const std::string what = dir_.string() + ": save version " + std::to_string(env.version());
  if (env.cell() != cell_)
    throw Error(what + ": cell '" + env.cell() + "' is not the store's '" + cell_ + "'");
  if (env.version() <= last_saved_) {
    throw Error(what + ": not above the last saved version " + std::to_string(last_saved_));
  }
  if (env.version() < highest_reserved_) {
    throw Error(what + ": below the reserved version " + std::to_string(highest_reserved_));
  }
  json doc = json::parse(to_json(BoxSet{env.version(), "cell", env.boxes()}));
  doc["cell"] = env.cell();
  doc["stamp_ns"] = env.stamp_ns();
  doc["blob"] = nullptr;
  if (blob) {
    write_file_atomically(blob_path(dir_, env.version()), *blob);
    doc["blob"] = {{"size", blob->size()}, {"fnv1a64", fnv1a64(*blob)}};
  }
  // The snapshot is the commit point: a crash before this rename leaves the previous version loadable.
  write_file_atomically(snapshot_path(dir_, env.version()), doc.dump(1) + "\n");
  last_saved_ = env.version();
  highest_used_ = std::max(highest_used_, env.version());
  good_.push_back(env.version());
  while (good_.size() > 2) {
    remove_quietly(snapshot_path(dir_, good_.front()));
    remove_quietly(blob_path(dir_, good_.front()));
    good_.erase(good_.begin());
  }
}

}  // namespace cellmap
