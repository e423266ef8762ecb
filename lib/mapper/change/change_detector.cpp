// SPDX-License-Identifier: Apache-2.0
#include "cellmap/change/change_detector.hpp"

#include <algorithm>
#include <cctype>
#include <istream>
#include <iterator>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>
#include <tuple>
#include <unordered_set>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

using Key = octomap::OcTreeKey;

bool zyx_less(const Key& a, const Key& b) {
  return std::make_tuple(a[2], a[1], a[0]) < std::make_tuple(b[2], b[1], b[0]);
}

// Calls visit(neighbour) for the 26 neighbours of `key` inside the key range.
template <class Visit>
void for_each_neighbour(const Key& key, Visit&& visit) {
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const int x = key[0] + dx, y = key[1] + dy, z = key[2] + dz;
        if (x < 0 || y < 0 || z < 0 || x > 0xffff || y > 0xffff || z > 0xffff) continue;
        visit(
            Key(static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), static_cast<std::uint16_t>(z)));
      }
    }
  }
}

constexpr const char* kStateHeader = "cellmap-change";

// Keys of `map` in (z, y, x) order, so that a state is written the same way every time.
template <class Map>
std::vector<Key> sorted_keys(const Map& map) {
  std::vector<Key> keys;
  keys.reserve(map.size());
  for (const auto& entry : map) keys.push_back(entry.first);
  std::sort(keys.begin(), keys.end(), zyx_less);
  return keys;
}

std::ostream& write_key(std::ostream& out, const Key& key) {
  return out << key[0] << ' ' << key[1] << ' ' << key[2];
}

// Reads the rest of a line, `count` unsigned integers separated by one space, from `in`; false if it is not.
bool read_line(std::istream& in, std::uint64_t* values, int count) {
  for (int i = 0; i < count; ++i) {
    if ((i > 0 && in.get() != ' ') || !std::isdigit(in.peek()) || !(in >> values[i])) return false;
  }
  return in.get() == '\n';
}

// The key of the first three values of a line, if each is a key coordinate.
std::optional<Key> key_of(const std::uint64_t* xyz) {
  if (xyz[0] > 0xffff || xyz[1] > 0xffff || xyz[2] > 0xffff) return std::nullopt;
  return Key(static_cast<std::uint16_t>(xyz[0]), static_cast<std::uint16_t>(xyz[1]),
             static_cast<std::uint16_t>(xyz[2]));
}

[[noreturn]] void bad(const std::string& field, const std::string& rule, double value) {
  std::ostringstream msg;
  msg << "change." << field << ": " << rule << ", got " << value;
  throw Error(msg.str());
}

}  // namespace

void ChangeConfig::validate() const {
  if (persist_sweeps < 1 || persist_sweeps > 1000)
    bad("persist_sweeps", "must be an integer in [1, 1000]", persist_sweeps);
  if (!(margin >= 0.0 && margin <= 10.0)) bad("margin", "must be in [0, 10] m", margin);
  if (min_voxels < 1 || min_voxels > 1000000)
    bad("min_voxels", "must be an integer in [1, 1000000]", min_voxels);
}

ChangeConfig ChangeConfig::from_yaml(YamlMap section) {
  ChangeConfig c;
  c.persist_sweeps = static_cast<int>(section.integer("persist_sweeps", c.persist_sweeps, 1, 1000));
  c.margin = section.number("margin", c.margin, 0.0, 10.0);
  c.min_voxels = static_cast<int>(section.integer("min_voxels", c.min_voxels, 1, 1000000));
  section.expect_all_read();
  return c;
}

ChangeDetector::ChangeDetector(const ChangeConfig& config) : config_(config) {
  config_.validate();
}

void ChangeDetector::write(std::ostream& out) const {
  out << kStateHeader << ' ' << sweep_ << ' ' << pending_.size() << ' ' << reported_.size() << '\n';
  for (const Key& key : sorted_keys(pending_)) {
    const Pending& p = pending_.at(key);
    write_key(out, key) << ' ' << (p.was_occupied ? 1 : 0) << ' ' << p.sweeps << '\n';
  }
  for (const Key& key : sorted_keys(reported_)) write_key(out, key) << ' ' << reported_.at(key) << '\n';
  if (!out) throw Error("change detector state: write failed");
}

void ChangeDetector::read(std::istream& in) {
  const auto fail = [](const std::string& what) { throw Error("change detector state: " + what); };
  std::string header(std::char_traits<char>::length(kStateHeader), '\0');
  std::uint64_t counts[3];  // sweep, pending, reported
  if (!in.read(header.data(), static_cast<std::streamsize>(header.size())) || header != kStateHeader ||
      in.get() != ' ' || !read_line(in, counts, 3)) {
    fail("bad header line");
  }
  const std::uint64_t sweep = counts[0];
  std::unordered_map<Key, Pending, Key::KeyHash> pending;
  for (std::uint64_t i = 0; i < counts[1]; ++i) {
    std::uint64_t v[5];  // x y z was_occupied sweeps_held
    const std::optional<Key> key = read_line(in, v, 5) ? key_of(v) : std::nullopt;
    if (!key || v[3] > 1 || v[4] < 1 || v[4] > 1000) fail("bad pending voxel " + std::to_string(i + 1));
    pending.emplace(*key, Pending{v[3] == 1, static_cast<int>(v[4])});
  }
  std::unordered_map<Key, std::uint64_t, Key::KeyHash> reported;
  for (std::uint64_t i = 0; i < counts[2]; ++i) {
    std::uint64_t v[4];  // x y z sweep
    const std::optional<Key> key = read_line(in, v, 4) ? key_of(v) : std::nullopt;
    if (!key || v[3] > sweep) fail("bad reported voxel " + std::to_string(i + 1));
    reported.emplace(*key, v[3]);
  }
  sweep_ = sweep;
  pending_ = std::move(pending);
  reported_ = std::move(reported);
}

ChangeSet ChangeDetector::update(const OccupancyUpdate& update, const OccupancyMap& map) {
  ChangeSet changes;
  changes.sweep = ++sweep_;
  record_flips(update);
  const ConfirmedFlips confirmed = confirm_held_flips();
  forget_old_reports();
  if (confirmed.empty()) return changes;

  // Grouped in sorted order so that the result is deterministic.
  KeySet grouped;
  for (const Key& seed : sorted_keys(confirmed)) {
    if (!grouped.insert(seed).second) continue;
    std::optional<ChangeRegion> region = grow_region(seed, confirmed, map, grouped);
    if (region) changes.regions.push_back(std::move(*region));
  }
  return changes;
}

std::vector<Key> ChangeDetector::pending_vanished() const {
  std::vector<Key> keys;
  for (const auto& [key, pending] : pending_) {
    if (pending.was_occupied) keys.push_back(key);
  }
  std::sort(keys.begin(), keys.end(), zyx_less);
  return keys;
}

void ChangeDetector::accept_vanished(const std::vector<Key>& keys) {
  for (const Key& key : keys) {
    const auto it = pending_.find(key);
    if (it != pending_.end() && it->second.was_occupied) pending_.erase(it);
  }
}

// A pending voxel that flips again is back at its confirmed state; any other starts pending.
void ChangeDetector::record_flips(const OccupancyUpdate& update) {
  auto flip = [&](const Key& key, bool now_occupied) {
    const auto it = pending_.find(key);
    if (it != pending_.end()) {
      pending_.erase(it);
    } else {
      pending_.emplace(key, Pending{!now_occupied, 0});
    }
  };
  for (const Key& key : update.appeared) flip(key, true);
  for (const Key& key : update.vanished) flip(key, false);
}

// The voxels whose new state has now held for persist_sweeps sweeps leave the pending ones.
ChangeDetector::ConfirmedFlips ChangeDetector::confirm_held_flips() {
  ConfirmedFlips confirmed;
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (++it->second.sweeps >= config_.persist_sweeps) {
      confirmed.emplace(it->first, !it->second.was_occupied);
      it = pending_.erase(it);
    } else {
      ++it;
    }
  }
  return confirmed;
}

// A reported object's voxels stop counting as "new" once its slower parts have had time to follow.
void ChangeDetector::forget_old_reports() {
  const std::uint64_t follow = 2 * static_cast<std::uint64_t>(config_.persist_sweeps);
  for (auto it = reported_.begin(); it != reported_.end();) {
    it = (sweep_ - it->second >= follow) ? reported_.erase(it) : std::next(it);
  }
}

// The confirmed voxels 26-connected to `seed` (added to `grouped`), as a region; nullopt when too few of
// them lie off the unchanged surface (jitter).
std::optional<ChangeRegion> ChangeDetector::grow_region(const Key& seed, const ConfirmedFlips& confirmed,
                                                        const OccupancyMap& map, KeySet& grouped) {
  ChangeRegion region;
  int off_surface_appeared = 0, off_surface_vanished = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  std::vector<Key> stack = {seed};
  while (!stack.empty()) {
    const Key key = stack.back();
    stack.pop_back();
    const bool appeared = confirmed.at(key);
    (appeared ? region.appeared : region.vanished).push_back(key);
    const Eigen::Vector3d c = map.centre(key);
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
    bool touches_unchanged_surface = false;
    for_each_neighbour(key, [&](const Key& n) {
      if (confirmed.count(n) != 0) {
        if (grouped.insert(n).second) stack.push_back(n);
      } else if (!touches_unchanged_surface && pending_.count(n) == 0 && reported_.count(n) == 0 &&
                 map.state(n) == VoxelState::occupied) {
        touches_unchanged_surface = true;
      }
    });
    if (!touches_unchanged_surface) ++(appeared ? off_surface_appeared : off_surface_vanished);
  }
  // Counted per kind: a surface voxel that jitters to its neighbour is one vanished and one appeared voxel,
  // which together are not an object arriving or leaving.
  if (std::max(off_surface_appeared, off_surface_vanished) < config_.min_voxels) return std::nullopt;
  for (const Key& key : region.appeared) reported_.emplace(key, sweep_);
  std::sort(region.appeared.begin(), region.appeared.end(), zyx_less);
  std::sort(region.vanished.begin(), region.vanished.end(), zyx_less);
  const double half = 0.5 * map.tree().getResolution();
  region.bounds = Region{lo.array() - half, hi.array() + half}.grown(config_.margin);
  return region;
}

}  // namespace cellmap
