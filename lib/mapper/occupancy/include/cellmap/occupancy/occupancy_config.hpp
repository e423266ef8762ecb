// SPDX-License-Identifier: Apache-2.0
#pragma once
// Parameters of the occupancy map: OctoMap's probabilistic sensor model plus the range and threads of the
// sweep fusion.

#include "cellmap/config/yaml_map.hpp"

namespace cellmap {

/// How sweeps are fused into the occupancy map. Probabilities are OctoMap's sensor model: each sweep adds
/// log-odds(hit) to every voxel holding a point and log-odds(miss) to every voxel a ray crosses, clamped to
/// [log-odds(clamp_min), log-odds(clamp_max)]; a voxel is occupied when its probability is >=
/// occupied_threshold. The defaults are OctoMap's own defaults at 2 cm.
struct OccupancyConfig final {
  /// Voxel edge, metres (YAML `occupancy.resolution`).
  double resolution = 0.02;
  /// P(occupied | point in voxel), in (0.5, 1) (`occupancy.hit`).
  double hit = 0.7;
  /// P(occupied | ray crosses voxel), in (0, 0.5) (`occupancy.miss`).
  double miss = 0.4;
  /// Lower probability clamp (`occupancy.clamp_min`).
  double clamp_min = 0.1192;
  /// Upper probability clamp (`occupancy.clamp_max`).
  double clamp_max = 0.971;
  /// Probability at or above which a voxel is occupied (`occupancy.occupied_threshold`).
  double occupied_threshold = 0.5;
  /// Metres from the sensor origin; a farther point only clears free space up to this range and marks nothing
  /// occupied (`occupancy.max_range`).
  double max_range = 5.0;
  /// Ray-casting threads (`occupancy.threads`); the result does not depend on it.
  int threads = 2;

  /// @throws Error naming the field if a value is out of range: resolution in [0.001, 1] m; 0.5 < hit < 1;
  /// 0 < miss < 0.5; 0 < clamp_min < occupied_threshold < clamp_max < 1; max_range in (0, 100] m;
  /// threads in [1, 64].
  void validate() const;

  /// Sweeps of pure free-space evidence that turn a voxel at the upper clamp into a free one: the smallest n
  /// with logodds(clamp_max) + n · logodds(miss) < logodds(occupied_threshold). With the defaults, 9. A
  /// removed object has vanished from the map after this many sweeps that see through where it was.
  [[nodiscard]] int sweeps_to_clear() const;

  /// Sweeps of hits that turn a voxel at the lower clamp (well-observed free space) into an occupied one: the
  /// smallest n with logodds(clamp_min) + n · logodds(hit) >= logodds(occupied_threshold). With the
  /// defaults, 3. An object put into observed free space is in the map after this many sweeps (in unknown
  /// space after 1).
  [[nodiscard]] int sweeps_to_occupy() const;

  /// Reads the `occupancy` section (the map passed is that section; absent keys keep their defaults).
  /// Keys: resolution, hit, miss, clamp_min, clamp_max, occupied_threshold, max_range, threads.
  /// @throws Error naming the key ("occupancy.hit: ...") for unknown keys, wrong types or bad ranges.
  [[nodiscard]] static OccupancyConfig from_yaml(YamlMap section);
};

}  // namespace cellmap
