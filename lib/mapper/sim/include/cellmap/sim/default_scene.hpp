// SPDX-License-Identifier: Apache-2.0
#pragma once
// The bundled default scene (config/cell.yaml), embedded at build time.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include "cellmap/sim/scene.hpp"

namespace cellmap::sim {

/// The text of config/cell.yaml as it was when the library was built.
[[nodiscard]] const char* default_scene_yaml();

/// The parsed default scene: a gantry over a 3 m × 2 m table with pallets, a fixture and a box stack, and the
/// paper's three sensors on the tool. It must not use a URDF (no files are at hand).
[[nodiscard]] Scene default_scene();

}  // namespace cellmap::sim
