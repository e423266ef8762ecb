// SPDX-License-Identifier: Apache-2.0
#pragma once
// Changes to a simulated scene between sweeps: how tests and `cellmap inject` plant synthetic changes. The
// edit is the cellmap/sim/scene_edits topic's value type, transport::SceneEdit.

#include <cstddef>
#include <string>

#include "cellmap/sim/scene.hpp"
#include "cellmap/transport/messages.hpp"

namespace cellmap::sim {

/// The most obstacles an edited scene holds: every sweep casts its rays against each, so a flood of
/// add-box edits would slow the simulated cell down without this bound.
inline constexpr std::size_t kMaxSceneObstacles = 256;

/// Applies `edit` to `scene` (its `cell` is not looked at); on error the scene is unchanged. Add-box adds a
/// box obstacle (centre, half extents, yaw about the cell's z axis; an empty name is replaced by a free one,
/// "added_1", "added_2", ...), remove drops the named obstacle, move puts its centre at `center`. Returns the
/// name of the obstacle added, removed or moved. @throws Error if the named obstacle does not exist (remove,
/// move), the name is taken or the scene holds kMaxSceneObstacles already (add), the added box has a
/// non-positive size or non-finite pose, or the move's centre is not finite.
std::string apply(Scene& scene, const transport::SceneEdit& edit);

}  // namespace cellmap::sim
