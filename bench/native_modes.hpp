// SPDX-License-Identifier: Apache-2.0
#pragma once
// Native depth modes of the default cell's cameras that the simulator's models do not default to.

#include "cellmap/sim/scene.hpp"

namespace cellmap::bench {

/// The RealSense D435's 848 × 480 depth mode (≈ 89° × 58° field of view; the simulator's default mode is
/// 640 × 480), with the default mode's range limits.
inline PinholeIntrinsics d435_848x480() {
  PinholeIntrinsics k = sim::default_intrinsics(sim::SensorModel::kRealsenseD435);
  k.width = 848;
  k.height = 480;
  k.fx = k.fy = 430.0;
  k.cx = 423.5;
  k.cy = 239.5;
  return k;
}

}  // namespace cellmap::bench
