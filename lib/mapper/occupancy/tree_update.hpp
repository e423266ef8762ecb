// SPDX-License-Identifier: Apache-2.0
#pragma once
// Applying a sweep's KeyUpdate to the OcTree: each brick's subtree descended once, with OctoMap's per-voxel
// update rules.

#include <octomap/OcTree.h>

#include "cellmap/occupancy/occupancy_map.hpp"
#include "key_update.hpp"

namespace cellmap {

/// Updates every voxel of `keys` in `tree` exactly as updateNode(key, occupied, lazy_eval = true) would
/// (hit for occupied voxels, miss for free ones, clamped), refreshes and prunes the inner nodes it visited as
/// OctoMap's non-lazy insert does, and appends the voxels whose occupied state flipped to `out.appeared` /
/// `out.vanished` (unsorted). Every leaf ends as per-voxel updateNode() calls would leave it.
void apply_key_update(const KeyUpdate& keys, octomap::OcTree& tree, OccupancyUpdate& out);

}  // namespace cellmap
