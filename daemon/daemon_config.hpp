// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmapd's configuration: one YAML file, each stage's section read by that stage's own reader.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <vector>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/robot/robot.hpp"
#include "cellmap/ros2/environment_writers.hpp"
#include "cellmap/ros2/sensor_sources.hpp"
#include "cellmap/security/credentials.hpp"
#include "cellmap/sensor/sensor_config.hpp"
#include "cellmap/sim/scene.hpp"
#include "cellmap/sweep/sweep_assembler.hpp"

namespace cellmap::daemon {

/// What one sensor of the cell is (`kind` of an entry of `sources`): a sensor of the simulated cell (the
/// default: no hardware needed), a depth camera (a replay directory, an OpenNI2 or a V4L2 device) or a
/// ROS 2 driver's topic (sensor_msgs/msg/PointCloud2 or LaserScan). All but sim are posed as cameras.
enum class SourceKind { kSim, kReplay, kOpenNI2, kV4l2, kPointCloud2, kLaserScan };
/// The config's spelling: sim | replay | openni2 | v4l2 | pointcloud2 | laserscan.
[[nodiscard]] const char* to_string(SourceKind kind);

/// One entry of `sources` (or the single `source` section, read as a list of one). Each entry is laid over
/// the built-in `source` section, so it names only what it changes.
struct SourceConfig final {
  /// Where the entry is in the config (`source`, `sources[1]`): messages about it name its keys from there.
  std::string key = "source";
  SourceKind kind = SourceKind::kSim;  ///< `kind`
  /// `scene` (sim): scene YAML (relative paths are relative to the config file); empty = the embedded
  /// default cell (config/cell.yaml). Every sim entry names the same scene.
  std::filesystem::path scene;
  /// `sensor`: sim: the scene's sensor; cameras: the name frames, logs and the status topic give the camera.
  /// Unique among the sources.
  std::string sensor = "kinect";
  bool noise = true;  ///< `noise` (sim, the same for every sim entry): false = exact depths (tests)
  /// `no_return_range`: metres a pixel without a return clears along its line of sight, [0, 100]; 0 = none
  /// (SweepFrame::no_return_range: time-of-flight cameras only).
  double no_return_range = 0.0;
  /// Cameras: `mount: tool | cell` with `pose` (sim::read_mount; `X_ES` is read as the old spelling of a
  /// tool mount's pose): on the tool at camera.X_ES (posed through the robot), or fixed at X_CS. A simulated
  /// sensor is mounted by its scene.
  sim::Mount mount = sim::Mount::kTool;
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  /// Cameras: `pose_tolerance` and the settings of the chosen kind (`openni2`, `v4l2` or `replay`; a relative
  /// replay directory is relative to the config file); camera.X_ES is the tool mount's pose.
  SensorConfig camera;
  /// Cameras: period = `sweep_period` (the frame time one sweep spans), max_frames = `sweep_frames`,
  /// pose_wait = `pose_wait`.
  SweepParams grouping;
  /// pointcloud2 and laserscan: the settings of that kind (`topic` and `frame_id` required, `reliability`,
  /// `frame_timeout`); stamps are checked against kMaxPoseSkew's 5 s like the robot's samples.
  ros2::TopicInput ros2;

  [[nodiscard]] bool is_camera() const { return kind != SourceKind::kSim; }
  [[nodiscard]] bool is_ros2() const {
    return kind == SourceKind::kPointCloud2 || kind == SourceKind::kLaserScan;
  }
};

/// The `ros2` section: ROS 2 nodes on the same DDS domain (docs/ros2.md). Everything off by default.
struct Ros2Config final {
  /// `joint_states`: a sensor_msgs/msg/JointState topic posing the robot instead of cellmap/robot_joints;
  /// empty = cellmap/robot_joints.
  std::string joint_states;
  /// `collision_objects` (`enabled`, `topic`, `frame_id`, `unknown_boxes`): the boxes for MoveIt; nullopt =
  /// off.
  std::optional<ros2::TopicOutput> collision_objects;
  /// `markers` (`enabled`, `topic`, `frame_id`, `unknown_boxes`): the boxes for RViz; nullopt = off.
  std::optional<ros2::TopicOutput> markers;
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
  /// `frame_backlog`: frames that wait to be fused into their sweep; when it is full the oldest is dropped.
  std::size_t frame_backlog = 16;
  /// `sweep_backlog`: fused sweeps that wait for change detection and re-segmentation; when it is full the
  /// oldest is dropped.
  std::size_t sweep_backlog = 8;
  std::uint32_t delta_depth = 16;  ///< `delta_depth`: deltas kept for late joiners
  std::string log_level = "info";  ///< `log_level`: trace | debug | info | warn | error
  /// `security` section (`directory`, `role`; --security, --role override): DDS Security with the credentials
  /// `cellmap security init` wrote (a relative directory is relative to the config file); nullopt = off.
  std::optional<security::Setting> security;
  /// `sources` (a list) or `source` (one sensor, the older form; not both): every sensor of the cell, all
  /// simulated (one scene) or all cameras. Never empty.
  std::vector<SourceConfig> sources;
  /// `robot` section (`gantry: {...}` or `urdf: {...}`, sim::read_robot; relative paths against the config
  /// file): the robot whose joints cellmap/robot_joints reports, posing tool-mounted cameras and the self
  /// filter. nullopt (no section): a simulated cell uses its scene's robot; cameras on the tool are posed
  /// from cellmap/robot_state (tool poses only).
  std::optional<Robot> robot;
  /// The sections `occupancy`, `change`, `segment` and `reconcile`: what makes the map and the boxes.
  CellPipelineConfig pipeline;
  Ros2Config ros2;

  /// True if any ROS 2 topic is read or written (a source of a ROS 2 kind, or the `ros2` section).
  [[nodiscard]] bool uses_ros2() const;
  /// True if the sources are the simulated cell's sensors.
  [[nodiscard]] bool simulated() const { return !sources.front().is_camera(); }

  /// Reads a config file laid over the built-in defaults (default_config_yaml(), key by key), so every key is
  /// optional.
  /// @throws Error naming the file and key for unknown keys, wrong types and out-of-range values.
  [[nodiscard]] static DaemonConfig load(const std::filesystem::path& file);
  /// As load(), on YAML text; `source` names it in messages and `base_dir` resolves relative paths.
  /// @throws ConfigErrors (an Error) with every problem read() finds.
  [[nodiscard]] static DaemonConfig parse(const std::string& yaml, const std::string& source,
                                          const std::filesystem::path& base_dir);
  /// As parse(), but reads on past a problem so that all of them are found (`cellmapd --check`): each
  /// top-level key, each section and each entry of `sources` is read on its own; one that fails keeps its
  /// default (a failed entry of `sources` is left out, so `sources` may be empty) and its problem, one line
  /// "<source>: <key>: <reason>", is appended to `problems`. A file that is not YAML is one problem.
  [[nodiscard]] static DaemonConfig read(const std::string& yaml, const std::string& source,
                                         const std::filesystem::path& base_dir,
                                         std::vector<std::string>& problems);
};

/// A config that does not load: every problem found, in the order found. what() is them all, joined by
/// "; " (one line).
class ConfigErrors final : public Error {
 public:
  explicit ConfigErrors(std::vector<std::string> problems);
  [[nodiscard]] const std::vector<std::string>& problems() const { return problems_; }

 private:
  std::vector<std::string> problems_;
};

/// What cellmapd's command line sets over the config's keys: `--domain`, `--state-dir`, `--security` with
/// `--role`. Unset ones leave the config's value.
struct ConfigOverrides final {
  std::optional<int> domain;
  std::optional<std::filesystem::path> state_dir;
  std::optional<security::Setting> security;

  void apply_to(DaemonConfig& config) const;
};

/// ROS 2 nodes hold none of the cell's credentials: a daemon that talked to them with DDS Security on would
/// be silently unprotected on those topics. (DaemonConfig::parse checks it; the command line's --security
/// needs it checked again.) @throws Error saying so if security is on and uses_ros2().
void check_ros2_security(const DaemonConfig& config);

}  // namespace cellmap::daemon
