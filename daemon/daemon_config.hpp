#pragma once
// cellmapd's configuration: one YAML file, each stage's section read by that stage's own reader.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "cellmap/change/change_detector.hpp"
#include "cellmap/environment/reconcile.hpp"
#include "cellmap/occupancy/occupancy_config.hpp"
#include "cellmap/segment/pipeline.hpp"

namespace cellmap::daemon {

/// Where sweeps come from. Only the simulated cell needs no hardware; it is the default.
struct SourceConfig final {
  std::string kind = "sim";  ///< `source.kind`: sim
  /// `source.scene`: scene YAML (relative paths are relative to the config file); empty = the embedded
  /// default cell (config/cell.yaml).
  std::filesystem::path scene;
  std::string sensor = "kinect";  ///< `source.sensor`: name of the scene's sensor to sweep with
  bool noise = true;              ///< `source.noise`: false = exact depths (tests)
};

/// The text of config/cellmapd.yaml, embedded at build time: the built-in defaults.
[[nodiscard]] const char* default_config_yaml();

/// Everything cellmapd reads at start. SIGHUP re-reads the file and applies `log_level` and `sweep_period`;
/// the other keys need a restart (they shape the map and the published versions).
struct DaemonConfig final {
  std::string cell = "cell-1";                ///< `cell`: the cell id the environment is published under
  int domain = 0;                             ///< `domain`: DDS domain id (--domain overrides)
  std::filesystem::path state_dir = "state";  ///< `state_dir` (--state-dir overrides); relative to the cwd
  double sweep_period = 0.5;   ///< `sweep_period`: seconds between sweep starts (0 = as fast as processed)
  double status_period = 1.0;  ///< `status_period`: seconds between status messages
  std::uint32_t delta_depth = 16;  ///< `delta_depth`: deltas kept for late joiners
  std::string log_level = "info";  ///< `log_level`: trace | debug | info | warn | error
  SourceConfig source;
  OccupancyConfig occupancy;   ///< `occupancy` section
  ChangeConfig change;         ///< `change` section
  SegmentConfig segment;       ///< `segment` section: the keys of config/segment.yaml
  ReconcileOptions reconcile;  ///< `reconcile` section

  /// Reads a config file laid over the built-in defaults (default_config_yaml(), key by key), so every key is
  /// optional.
  /// @throws Error naming the file and key for unknown keys, wrong types and out-of-range values.
  [[nodiscard]] static DaemonConfig load(const std::filesystem::path& file);
  /// As load(), on YAML text; `source` names it in messages and `base_dir` resolves relative paths.
  [[nodiscard]] static DaemonConfig parse(const std::string& yaml, const std::string& source,
                                          const std::filesystem::path& base_dir);
};

}  // namespace cellmap::daemon
