// SPDX-License-Identifier: Apache-2.0
#pragma once
// A version of a cell's collision environment and the delta between two versions.

#include <cstdint>
#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"

namespace cellmap {

/// One version of a cell's collision environment: the boxes (in the cell frame C) that make it up. Immutable
/// value type; an Environment that exists is valid: its boxes are sorted by id and no id repeats.
class Environment final {
 public:
  /// The empty environment of `cell` before any version (version 0, no boxes, stamp 0).
  explicit Environment(std::string cell = "cell");
  /// @param version  strictly increasing per cell; 0 means "nothing published yet".
  /// @param stamp_ns when the version was made, nanoseconds since the Unix epoch (system clock).
  /// @param boxes    in any order; stored sorted by id.
  /// @throws Error if `cell` is empty or two boxes share an id.
  Environment(std::string cell, std::uint64_t version, std::int64_t stamp_ns, std::vector<Box> boxes);

  [[nodiscard]] const std::string& cell() const { return cell_; }
  [[nodiscard]] std::uint64_t version() const { return version_; }
  [[nodiscard]] std::int64_t stamp_ns() const { return stamp_ns_; }
  /// Sorted by id.
  [[nodiscard]] const std::vector<Box>& boxes() const { return boxes_; }
  /// The box with `id`, or nullptr. O(log n).
  [[nodiscard]] const Box* find(std::uint64_t id) const;

  /// Same cell, version, stamp and boxes (every field of every box compared exactly).
  friend bool operator==(const Environment& a, const Environment& b);
  friend bool operator!=(const Environment& a, const Environment& b) { return !(a == b); }

 private:
  std::string cell_;
  std::uint64_t version_ = 0;
  std::int64_t stamp_ns_ = 0;
  std::vector<Box> boxes_;
};

/// What changed from version `from_version` to `to_version` of `cell`. `added` and `modified` carry the
/// boxes as they are in `to_version`; `removed` the ids gone. Each list is sorted by id.
struct EnvironmentDelta final {
  std::string cell;
  std::uint64_t from_version = 0;
  std::uint64_t to_version = 0;
  std::int64_t stamp_ns = 0;  ///< the stamp of `to_version`
  std::vector<Box> added;
  std::vector<Box> modified;
  std::vector<std::uint64_t> removed;

  /// True when no box changed (only the version moved).
  [[nodiscard]] bool empty() const { return added.empty() && modified.empty() && removed.empty(); }
};

/// True when every field of `a` and `b` is exactly equal (id, center, half extents, rotation, points).
[[nodiscard]] bool same_box(const Box& a, const Box& b);

/// The delta that turns `before` into `after`: a box whose id is in both but any field differs is modified.
/// @throws Error if the cells differ or after.version() <= before.version().
[[nodiscard]] EnvironmentDelta diff(const Environment& before, const Environment& after);

/// Applies `delta` to `env`: the result has version delta.to_version and stamp delta.stamp_ns.
/// @throws Error naming the field if the cell differs, delta.from_version != env.version(), to_version is not
/// above from_version, an added id is already present, or a modified/removed id is absent.
[[nodiscard]] Environment apply(const Environment& env, const EnvironmentDelta& delta);

}  // namespace cellmap
