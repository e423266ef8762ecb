// SPDX-License-Identifier: Apache-2.0
#pragma once
// The voxels one sweep observes — occupied endpoints and crossed free space — computed without touching the
// tree, so that the tree is then updated once per voxel, subtree by subtree, instead of once per ray step.

#include <octomap/OcTree.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "cellmap/sweep/sweep.hpp"

namespace cellmap {

/// A key as one number z:y:x (16 bits each), so that numeric order is the (z, y, x) order of a dense index.
[[nodiscard]] inline std::uint64_t pack_key(const octomap::OcTreeKey& k) {
  return std::uint64_t{k[0]} | (std::uint64_t{k[1]} << 16) | (std::uint64_t{k[2]} << 32);
}
[[nodiscard]] inline octomap::OcTreeKey unpack_key(std::uint64_t p) {
  return octomap::OcTreeKey(static_cast<std::uint16_t>(p & 0xffff),
                            static_cast<std::uint16_t>((p >> 16) & 0xffff),
                            static_cast<std::uint16_t>(p >> 32));
}

/// 16 × 16 × 16 leaf voxels whose keys share all but their 4 lowest bits: exactly one OcTree subtree 4 levels
/// above the leaves. Bit i of a mask is the voxel whose local key offsets (x, y, z) interleave to i with x in
/// the lowest bit of each triple and z in the highest — OctoMap's child order, so each child subtree is a
/// contiguous bit range.
struct KeyBrick final {
  static constexpr int kEdge = 16;
  static constexpr int kVoxels = kEdge * kEdge * kEdge;
  octomap::OcTreeKey base;  ///< smallest key of the brick (components multiples of 16)
  std::array<std::uint64_t, kVoxels / 64> occupied{};  ///< voxels that get a hit
  std::array<std::uint64_t, kVoxels / 64> free{};      ///< voxels that get free-space evidence

  /// Local bit index of a key inside this brick (its 4 lowest bits per axis, interleaved).
  [[nodiscard]] static int local_index(const octomap::OcTreeKey& key);
  /// The key of local bit `index`.
  [[nodiscard]] octomap::OcTreeKey key(int index) const;
};

/// The OcTree keys one sweep updates (leaf level), grouped in bricks. No voxel is both occupied and free: a
/// voxel that holds a point of this sweep is not also cleared (OctoMap's rule).
struct KeyUpdate final {
  std::vector<KeyBrick> bricks;  ///< non-empty bricks in the OcTree's depth-first order
  std::size_t occupied_count = 0;
  std::size_t free_count = 0;

  /// The occupied / free keys, sorted by (z, y, x) (for tests and diagnostics; allocates).
  [[nodiscard]] std::vector<octomap::OcTreeKey> occupied_keys() const;
  [[nodiscard]] std::vector<octomap::OcTreeKey> free_keys() const;
};

/// Computes the voxels `sweep` observes in the key space of `grid` (only its resolution and key layout are
/// used; the tree is not modified). Per scan, the points are first snapped to their voxel centres and
/// de-duplicated, then one ray is walked (Amanatides–Woo) from the scan's `origin_C` to each distinct
/// endpoint voxel. A point farther than `max_range` (metres, measured to its voxel centre) marks nothing
/// occupied; its ray clears free space up to `max_range` only. A scan's clear-only ray ends (`clear_C`) are
/// snapped the same way and walked like a point's ray, but mark nothing occupied: a clear-only ray to voxel k
/// clears exactly OctoMap's `computeRayKeys(origin, centre(k))`. Each thread de-duplicates the end voxels of
/// its own share of the points and clear-only ends (an end that a point of its share holds needs no
/// clear-only ray); an end voxel of two shares gets the same ray twice, which marks the same voxels. For a
/// one-scan sweep this equals OctoMap's
/// `computeDiscreteUpdate(scan, origin, free, occupied, max_range)`; for several scans it is the union over
/// the scans, with occupied winning over free across the whole sweep.
///
/// Non-finite points and points outside the tree's key range (±655 m at 2 cm) are skipped. Converts the
/// points and walks the rays on `threads` threads (≥ 1: the caller and parallel_for's helper threads, kept
/// for the calling thread's next call); the result does not depend on the count. Several threads may call it
/// at once (it only reads `grid`). Memory: per thread, a bit set over the bounding key box of the sweep
/// (≈ 1.2 MB for a 5 × 5 × 3 m box at 2 cm) and one over the box of its share's end voxels; boxes beyond 2^28
/// voxels fall back to sorting keys (slower, same result).
/// @throws Error if a scan origin is not finite or outside the tree's key range, or `max_range` is not > 0.
[[nodiscard]] KeyUpdate compute_key_update(const Sweep& sweep, const octomap::OcTree& grid, double max_range,
                                           int threads);

/// The key update of a sweep gathered scan by scan: the union of the scans' updates, occupied winning over
/// free across all of them, which is exactly compute_key_update() of the sweep of those scans (each scan's
/// voxels depend on that scan alone). Memory: one brick (1 KB) per brick any scan touched. Not thread-safe.
class KeyUpdateUnion final {
 public:
  /// Adds the update of one more scan of the sweep (compute_key_update of a sweep holding that scan).
  void add(const KeyUpdate& scan_update);
  /// Adds what `other` gathered (other scans of the same sweep, e.g. on another thread); empties `other`.
  void merge(KeyUpdateUnion& other);
  /// Whether no scan added a voxel yet.
  [[nodiscard]] bool empty() const { return bricks_.empty(); }
  /// Bricks gathered so far.
  [[nodiscard]] std::size_t size() const { return bricks_.size(); }
  /// The sweep's update (bricks in depth-first order, counts set); the union is empty afterwards.
  [[nodiscard]] KeyUpdate take();

 private:
  void add(const std::vector<KeyBrick>& bricks);

  std::vector<KeyBrick> bricks_;                          // in the order first touched
  std::unordered_map<std::uint64_t, std::size_t> index_;  // packed brick base → position in bricks_
};

}  // namespace cellmap
