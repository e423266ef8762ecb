// SPDX-License-Identifier: Apache-2.0
#include "cellmap/environment/environment.hpp"

#include <algorithm>
#include <map>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"

namespace cellmap {
namespace {

bool by_id(const Box& a, const Box& b) {
  return a.id < b.id;
}

// Cell names come from the network too: quoted on one line.
std::string version_text(const std::string& cell, std::uint64_t version) {
  return "environment '" + single_line(cell) + "' version " + std::to_string(version);
}

}  // namespace

Environment::Environment(std::string cell) : Environment(std::move(cell), 0, 0, {}) {}

Environment::Environment(std::string cell, std::uint64_t version, std::int64_t stamp_ns,
                         std::vector<Box> boxes)
    : cell_(std::move(cell)), version_(version), stamp_ns_(stamp_ns), boxes_(std::move(boxes)) {
  if (cell_.empty()) throw Error("environment: cell id must not be empty");
  std::sort(boxes_.begin(), boxes_.end(), by_id);
  const auto twin = std::adjacent_find(boxes_.begin(), boxes_.end(),
                                       [](const Box& a, const Box& b) { return a.id == b.id; });
  if (twin != boxes_.end()) {
    throw Error(version_text(cell_, version_) + ": box id " + std::to_string(twin->id) + " appears twice");
  }
}

const Box* Environment::find(std::uint64_t id) const {
  Box key;
  key.id = id;
  const auto it = std::lower_bound(boxes_.begin(), boxes_.end(), key, by_id);
  return it != boxes_.end() && it->id == id ? &*it : nullptr;
}

bool same_box(const Box& a, const Box& b) {
  return a.id == b.id && a.center == b.center && a.half_extents == b.half_extents &&
         a.rotation.coeffs() == b.rotation.coeffs() && a.points == b.points && a.space == b.space;
}

bool operator==(const Environment& a, const Environment& b) {
  return a.cell_ == b.cell_ && a.version_ == b.version_ && a.stamp_ns_ == b.stamp_ns_ &&
         std::equal(a.boxes_.begin(), a.boxes_.end(), b.boxes_.begin(), b.boxes_.end(), same_box);
}

EnvironmentDelta diff(const Environment& before, const Environment& after) {
  if (before.cell() != after.cell()) {
    throw Error("diff: cells differ ('" + before.cell() + "' vs '" + after.cell() + "')");
  }
  if (after.version() <= before.version()) {
    throw Error("diff: " + version_text(after.cell(), after.version()) + " is not after version " +
                std::to_string(before.version()));
  }
  EnvironmentDelta delta;
  delta.cell = after.cell();
  delta.from_version = before.version();
  delta.to_version = after.version();
  delta.stamp_ns = after.stamp_ns();
  // Both box lists are sorted by id: one merge pass.
  auto old_it = before.boxes().begin();
  auto new_it = after.boxes().begin();
  while (old_it != before.boxes().end() || new_it != after.boxes().end()) {
    if (new_it == after.boxes().end() || (old_it != before.boxes().end() && old_it->id < new_it->id)) {
      delta.removed.push_back((old_it++)->id);
    } else if (old_it == before.boxes().end() || new_it->id < old_it->id) {
      delta.added.push_back(*new_it++);
    } else {
      if (!same_box(*old_it, *new_it)) delta.modified.push_back(*new_it);
      ++old_it;
      ++new_it;
    }
  }
  return delta;
}

Environment apply(const Environment& env, const EnvironmentDelta& delta) {
  const std::string what = "delta " + std::to_string(delta.from_version) + " -> " +
                           std::to_string(delta.to_version) + " for '" + single_line(delta.cell) + "'";
  if (delta.cell != env.cell())
    throw Error(what + ": cell: does not match '" + single_line(env.cell()) + "'");
  if (delta.from_version != env.version()) {
    throw Error(what + ": from_version: does not match " + version_text(env.cell(), env.version()));
  }
  if (delta.to_version <= delta.from_version) throw Error(what + ": to_version: must be above from_version");
  std::map<std::uint64_t, Box> boxes;
  for (const Box& box : env.boxes()) boxes.emplace(box.id, box);
  for (const std::uint64_t id : delta.removed) {
    if (boxes.erase(id) == 0)
      throw Error(what + ": removed: box id " + std::to_string(id) + " is not present");
  }
  for (const Box& box : delta.modified) {
    const auto it = boxes.find(box.id);
    if (it == boxes.end())
      throw Error(what + ": modified: box id " + std::to_string(box.id) + " is not present");
    it->second = box;
  }
  for (const Box& box : delta.added) {
    if (!boxes.emplace(box.id, box).second) {
      throw Error(what + ": added: box id " + std::to_string(box.id) + " is already present");
    }
  }
  std::vector<Box> result;
  result.reserve(boxes.size());
  for (auto& entry : boxes) result.push_back(entry.second);
  return Environment(env.cell(), delta.to_version, delta.stamp_ns, std::move(result));
}

}  // namespace cellmap
