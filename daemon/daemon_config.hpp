#pragma once
// cellmapd's configuration: one YAML file, each stage's section read by that stage's own reader.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/security/credentials.hpp"
#include "cellmap/sensor/sensor_config.hpp"
#include "cellmap/sweep/sweep_assembler.hpp"

namespace cellmap::daemon {

/// Where sweeps come from (`source.kind`): the simulated cell (the default: no hardware needed) or one depth
/// camera on the robot (a replay directory, an OpenNI2 or a V4L2 device).
enum class SourceKind { kSim, kReplay, kOpenNI2, kV4l2 };
/// The config's spelling: sim | replay | openni2 | v4l2.
[[nodiscard]] const char* to_string(SourceKind kind);

struct SourceConfig final {
  SourceKind kind = SourceKind::kSim;  ///< `source.kind`
  /// `source.scene` (sim): scene YAML (relative paths are relative to the config file); empty = the embedded
  /// default cell (config/cell.yaml).
  std::filesystem::path scene;
  /// `source.sensor`: sim: the scene's sensor that sweeps; cameras: the name frames, logs and the status
  /// topic give the camera.
  std::string sensor = "kinect";
  bool noise = true;  ///< `source.noise` (sim): false = exact depths (tests)
  /// Cameras: `source.X_ES`, `source.pose_tolerance` and the settings of the chosen kind (`source.openni2`,
  /// `source.v4l2` or `source.replay`; a relative replay directory is relative to the config file).
  SensorConfig camera;
  /// Cameras: period = `sweep_period` (the frame time one sweep spans), max_frames = `source.sweep_frames`,
  /// pose_wait = `source.pose_wait`.
  SweepGrouping grouping;

  [[nodiscard]] bool is_camera() const { return kind != SourceKind::kSim; }
};

/// The text of config/cellmapd.yaml, embedded at build time: the built-in defaults.
[[nodiscard]] const char* default_config_yaml();

/// Everything cellmapd reads at start. SIGHUP re-reads the file and applies `log_level` and `sweep_period`
/// (sim only: a camera's sweep grouping is fixed at start); the other keys need a restart (they shape the
/// map and the published versions).
struct DaemonConfig final {
  std::string cell = "cell-1";                ///< `cell`: the cell id the environment is published under
  int domain = 0;                             ///< `domain`: DDS domain id (--domain overrides)
  std::filesystem::path state_dir = "state";  ///< `state_dir` (--state-dir overrides); relative to the cwd
  double sweep_period = 0.5;   ///< `sweep_period`: seconds between sweep starts (0 = as fast as processed)
  double status_period = 1.0;  ///< `status_period`: seconds between status messages
  std::uint32_t delta_depth = 16;  ///< `delta_depth`: deltas kept for late joiners
  std::string log_level = "info";  ///< `log_level`: trace | debug | info | warn | error
  /// `security` section (`directory`, `role`; --security, --role override): DDS Security with the credentials
  /// `cellmap security init` wrote (a relative directory is relative to the config file); nullopt = off.
  std::optional<security::Setting> security;
  SourceConfig source;
  /// The sections `occupancy`, `change`, `segment` and `reconcile`: what makes the map and the boxes.
  CellPipelineConfig pipeline;

  /// Reads a config file laid over the built-in defaults (default_config_yaml(), key by key), so every key is
  /// optional.
  /// @throws Error naming the file and key for unknown keys, wrong types and out-of-range values.
  [[nodiscard]] static DaemonConfig load(const std::filesystem::path& file);
  /// As load(), on YAML text; `source` names it in messages and `base_dir` resolves relative paths.
  [[nodiscard]] static DaemonConfig parse(const std::string& yaml, const std::string& source,
                                          const std::filesystem::path& base_dir);
};

}  // namespace cellmap::daemon
