// SPDX-License-Identifier: Apache-2.0
#pragma once
// One sensor's configuration: which source it is, its settings and its hand-eye extrinsic; and the factory
// that builds the source.
//
// YAML (one map per sensor; unknown keys are refused; defaults in brackets):
//   source: openni2 | v4l2 | replay              required
//   X_ES: {position: [x, y, z], rotation: [w, x, y, z]}   sensor pose in the tool frame [identity]
//         (YamlMap::pose; `translation` is read as another spelling of `position`)
//   pose_tolerance: 0.05                          seconds between a frame and each bracketing robot pose
//   openni2:  uri ["": first device; or a .oni file], width [640], height [480], fps [30],
//             format [DEPTH_1_MM | DEPTH_100_UM], intrinsics {fx, fy, cx, cy} [from the device's field of
//             view], min_range [0], max_range [10], max_depth_jump [0.02], smoothing_radius [0],
//             realtime_playback [true]
//   v4l2:     device [/dev/video0], width [848], height [480], fps [30],
//             intrinsics {fx, fy, cx, cy, depth_scale} [RealSense D435 defaults for the size],
//             min_range [0.3], max_range [10], max_depth_jump [0.05], smoothing_radius [2], buffers [4]
//   openni2 and v4l2: frame_timeout [2], reconnect {initial_backoff [0.5], max_backoff [10]}
//   replay:   directory (required), playback [recorded | fixed | fastest], speed [1], rate_hz [10]

#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <variant>

#include "cellmap/config/yaml_map.hpp"
#include "cellmap/sensor/depth_source.hpp"
#include "cellmap/sensor/openni2_source.hpp"
#include "cellmap/sensor/replay_source.hpp"
#include "cellmap/sensor/v4l2_source.hpp"

namespace cellmap {

struct SensorConfig final {
  std::string name;
  Eigen::Isometry3d X_ES = Eigen::Isometry3d::Identity();  ///< hand-eye extrinsic
  double pose_tolerance = 0.05;                            ///< seconds, for the sensor's PoseBuffer
  std::variant<OpenNI2Config, V4l2Config, ReplayConfig> source;
};

/// Reads the map of sensor `name` (see the format above). @throws Error naming the file and key path.
[[nodiscard]] SensorConfig read_sensor_config(YamlMap& map, const std::string& name);

/// The per-source settings maps above, one reader each (cellmapd reads them from its `source` section).
/// Every key of the map must be known. @throws Error naming the file and key path.
[[nodiscard]] OpenNI2Config read_openni2_config(YamlMap settings, const std::string& name);
[[nodiscard]] V4l2Config read_v4l2_config(YamlMap settings, const std::string& name);
/// The directory may be absent here (""): the caller decides whether a replay is configured.
[[nodiscard]] ReplayConfig read_replay_config(YamlMap settings, const std::string& name);

/// Builds the configured source (not opened yet). @throws Error as the source's constructor.
[[nodiscard]] std::unique_ptr<DepthSource> make_depth_source(const SensorConfig& config);

}  // namespace cellmap
