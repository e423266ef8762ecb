// SPDX-License-Identifier: Apache-2.0
#include "daemon_config.hpp"

#include <algorithm>
#include <set>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/sim/scene.hpp"
#include "cellmap/transport/input_limits.hpp"

namespace cellmap::daemon {
namespace {

constexpr SourceKind kSourceKinds[] = {SourceKind::kSim,  SourceKind::kReplay,      SourceKind::kOpenNI2,
                                       SourceKind::kV4l2, SourceKind::kPointCloud2, SourceKind::kLaserScan};

std::optional<SourceKind> source_kind(const std::string& text) {
  for (const SourceKind kind : kSourceKinds) {
    if (text == to_string(kind)) return kind;
  }
  return std::nullopt;
}

// Reads on past a part of the config that fails, keeping its problem, so that every problem is reported.
class Problems {
 public:
  explicit Problems(std::vector<std::string>& found) : found_(found) {}
  /// Runs `read_part`; false (its problem kept) if it threw.
  template <typename ReadPart>
  bool read(ReadPart&& read_part) {
    try {
      read_part();
      return true;
    } catch (const Error& e) {
      found_.push_back(e.what());
      return false;
    }
  }

 private:
  std::vector<std::string>& found_;
};

std::string joined(const std::vector<std::string>& lines, const std::string& separator) {
  std::string text;
  for (const std::string& line : lines) text += (text.empty() ? "" : separator) + line;
  return text;
}

// The `security` section: off while `directory` is empty.
std::optional<security::Setting> read_security(YamlMap section, const std::filesystem::path& base_dir) {
  const std::string directory = section.get<std::string>("directory", "");
  const std::string role = section.get<std::string>("role", "daemon");
  std::optional<security::Setting> setting;
  try {
    if (!directory.empty()) setting = security::Setting{base_dir / directory, security::parse_role(role)};
  } catch (const Error&) {
    section.fail("role", "must be one of daemon, planner, robot, tool");
  }
  section.expect_all_read();
  return setting;
}

// A pose's position and rotation belong together (and `translation` spells `position`), so a pose given by
// the user replaces the default pose whole instead of merging into it.
bool is_pose(const YAML::Node& map) {
  return map["position"] || map["translation"] || map["rotation"];
}

// Lays `overlay` over `base`: maps merge key by key, anything else (and a pose) replaces. Maps of the overlay
// are checked as YamlMap checks them (plain keys), since it merges them before any YamlMap sees them.
YAML::Node overlay_on(const YAML::Node& base, const YAML::Node& overlay, const std::string& path,
                      const std::string& source) {
  if (!overlay || overlay.IsNull()) return YAML::Clone(base);
  if (!base.IsDefined() || !base.IsMap() || !overlay.IsMap() || is_pose(overlay)) return YAML::Clone(overlay);
  const YamlMap checked(overlay, path, source);
  YAML::Node merged = YAML::Clone(base);
  for (const auto& entry : overlay) {
    const std::string key = entry.first.Scalar();
    merged[key] = overlay_on(base[key], entry.second, checked.key_path(key), source);
  }
  return merged;
}

// A camera's mount: `mount` + `pose` (the one mount schema), or the older `X_ES` for a camera on the tool.
void read_camera_mount(YamlMap& section, SourceConfig& c) {
  if (section.has("X_ES")) {
    if (section.has("mount") || section.has("pose"))
      section.fail("X_ES", "is the older spelling of mount: tool with pose; give one of them");
    c.camera.X_ES = section.pose("X_ES");
    return;
  }
  const sim::SensorMount mount = sim::read_mount(section);
  c.mount = mount.mount;
  c.camera.X_ES = mount.X_ES;
  c.X_CS = mount.X_CS;
}

// A ROS 2 topic name of the config, checked as ros2::dds_topic checks it.
std::string read_ros2_topic(YamlMap& section, const char* key, const std::string& fallback) {
  const std::string topic = section.get<std::string>(key, fallback);
  try {
    (void)ros2::dds_topic(topic);
  } catch (const Error& e) {
    section.fail(key, e.what());
  }
  return topic;
}

// A `pointcloud2` or `laserscan` section; `chosen`: its kind is the entry's, so topic and frame_id are due.
ros2::TopicInput read_topic_input(YamlMap settings, bool chosen) {
  ros2::TopicInput input;
  const std::string topic = settings.get<std::string>("topic", "");
  if (chosen && topic.empty()) settings.fail("topic", "is required: the ROS 2 topic of the sensor's samples");
  if (!topic.empty()) input.topic = read_ros2_topic(settings, "topic", topic);
  input.frame_id = settings.get<std::string>("frame_id", "");
  if (chosen && input.frame_id.empty())
    settings.fail("frame_id", "is required: the header.frame_id of the sensor's samples");
  const std::string reliability = settings.get<std::string>("reliability", "best_effort");
  if (reliability != "best_effort" && reliability != "reliable")
    settings.fail("reliability", "must be best_effort or reliable");
  input.reliability =
      reliability == "reliable" ? ros2::Reliability::kReliable : ros2::Reliability::kBestEffort;
  input.frame_timeout = settings.number("frame_timeout", input.frame_timeout, 0.05, 3600.0);
  input.min_range = settings.number("min_range", input.min_range, 0.0, 100.0);
  settings.expect_all_read();
  return input;
}

// One source entry. Every camera kind's settings are read (so a misspelt key is found whichever kind is
// chosen); the chosen kind's become the camera.
SourceConfig read_source(YamlMap section, const std::string& key, double sweep_period,
                         const std::filesystem::path& base_dir) {
  SourceConfig c;
  c.key = key;
  const std::optional<SourceKind> kind = source_kind(section.get<std::string>("kind", to_string(c.kind)));
  if (!kind) section.fail("kind", "must be one of sim, replay, openni2, v4l2, pointcloud2, laserscan");
  c.kind = *kind;
  const std::string scene = section.get<std::string>("scene", "");
  if (!scene.empty()) c.scene = base_dir / scene;  // an absolute scene path replaces base_dir
  c.sensor = section.get<std::string>("sensor", c.sensor);
  if (c.sensor.empty()) section.fail("sensor", "must not be empty");
  c.noise = section.get<bool>("noise", c.noise);
  c.no_return_range = section.number("no_return_range", c.no_return_range, 0.0, 100.0);

  c.camera.name = c.sensor;
  if (c.is_camera()) {
    read_camera_mount(section, c);
  } else {
    for (const char* key : {"mount", "pose", "X_ES"}) {
      if (section.has(key)) section.fail(key, "a simulated sensor is mounted by its scene");
    }
  }
  c.camera.pose_tolerance = section.number("pose_tolerance", c.camera.pose_tolerance, 1e-6, 10.0);
  c.grouping.period = sweep_period;
  c.grouping.max_frames = static_cast<std::size_t>(section.integer("sweep_frames", 0, 0, 100000));
  c.grouping.pose_wait = section.number("pose_wait", c.grouping.pose_wait, 0.0, 60.0);
  const OpenNI2Config openni2 = read_openni2_config(section.child("openni2"), c.sensor);
  const V4l2Config v4l2 = read_v4l2_config(section.child("v4l2"), c.sensor);
  ReplayConfig replay = read_replay_config(section.child("replay"), c.sensor);
  const ros2::TopicInput cloud =
      read_topic_input(section.child("pointcloud2"), c.kind == SourceKind::kPointCloud2);
  const ros2::TopicInput scan =
      read_topic_input(section.child("laserscan"), c.kind == SourceKind::kLaserScan);
  if (c.kind == SourceKind::kPointCloud2) c.ros2 = cloud;
  if (c.kind == SourceKind::kLaserScan) c.ros2 = scan;
  if (c.kind == SourceKind::kOpenNI2) c.camera.source = openni2;
  if (c.kind == SourceKind::kV4l2) c.camera.source = v4l2;
  if (c.kind == SourceKind::kReplay) {
    if (replay.directory.empty()) section.child("replay").fail("directory", "is required for kind replay");
    replay.directory = (base_dir / replay.directory).string();  // an absolute directory replaces base_dir
    c.camera.source = replay;
  }
  section.expect_all_read();
  return c;
}

// The sources as a whole: unique names, all simulated (one scene, one noise setting) or all cameras.
void check_sources(const std::vector<SourceConfig>& sources, YamlMap& root, const std::string& key) {
  std::set<std::string> names;
  for (const SourceConfig& s : sources) {
    if (!names.insert(s.sensor).second) root.fail(key, "sensor '" + s.sensor + "' is named twice");
    if (s.is_camera() != sources.front().is_camera())
      root.fail(key, "simulated sensors and cameras cannot be mixed in one cell");
    if (!s.is_camera() && (s.scene != sources.front().scene || s.noise != sources.front().noise))
      root.fail(key, "every sim source must name the same scene and noise");
  }
}

// `sources` (each entry laid over the built-in `source` section) or the single `source` section. An entry
// that fails is left out.
std::vector<SourceConfig> read_sources(YamlMap& root, const YamlMap& user, const YamlMap& defaults,
                                       double sweep_period, const std::filesystem::path& base_dir,
                                       Problems& problems) {
  std::vector<SourceConfig> sources;
  const YAML::Node list = root.node("sources");
  if (!list) {
    problems.read(
        [&] { sources.push_back(read_source(root.child("source"), "source", sweep_period, base_dir)); });
    return sources;
  }
  (void)root.node("source");  // the built-in section: the entries' defaults
  problems.read([&] {
    if (user.has("source"))
      root.fail("source", "give either source (one sensor) or sources (a list), not both");
  });
  if (!list.IsSequence() || list.size() == 0) {
    problems.read([&] { root.fail("sources", "must be a non-empty list of sensors"); });
    return sources;
  }
  bool every_entry_read = true;
  for (std::size_t i = 0; i < list.size(); ++i) {
    every_entry_read &= problems.read([&] {
      const std::string path = "sources[" + std::to_string(i) + "]";
      if (!list[i].IsMap()) root.fail(path, "must be a map (kind, sensor, mount, ...)");
      const YAML::Node entry = overlay_on(defaults.node()["source"], list[i], path, root.source());
      sources.push_back(read_source(YamlMap(entry, path, root.source()), path, sweep_period, base_dir));
    });
  }
  if (every_entry_read) problems.read([&] { check_sources(sources, root, "sources"); });
  return sources;
}

// The `robot` section: none when absent or empty.
std::optional<Robot> read_daemon_robot(YamlMap& root, const std::filesystem::path& base_dir) {
  const YAML::Node node = root.node("robot");
  if (!node || node.IsNull() || (node.IsMap() && node.size() == 0)) return std::nullopt;
  return sim::read_robot(YamlMap(node, "robot", root.source()), base_dir.string());
}

// An output of the `ros2` section: nullopt unless enabled.
std::optional<ros2::TopicOutput> read_topic_output(YamlMap section) {
  const bool enabled = section.get<bool>("enabled", false);
  ros2::TopicOutput output;
  output.topic = read_ros2_topic(section, "topic", "");
  output.frame_id = section.get<std::string>("frame_id", output.frame_id);
  if (output.frame_id.empty()) section.fail("frame_id", "must not be empty");
  output.unknown_boxes = section.get<bool>("unknown_boxes", output.unknown_boxes);
  section.expect_all_read();
  return enabled ? std::optional(output) : std::nullopt;
}

Ros2Config read_ros2(YamlMap section) {
  Ros2Config c;
  c.joint_states = section.get<std::string>("joint_states", "");
  if (!c.joint_states.empty()) c.joint_states = read_ros2_topic(section, "joint_states", c.joint_states);
  c.collision_objects = read_topic_output(section.child("collision_objects"));
  c.markers = read_topic_output(section.child("markers"));
  section.expect_all_read();
  return c;
}

}  // namespace

const char* to_string(SourceKind kind) {
  switch (kind) {
    case SourceKind::kSim:
      return "sim";
    case SourceKind::kReplay:
      return "replay";
    case SourceKind::kOpenNI2:
      return "openni2";
    case SourceKind::kV4l2:
      return "v4l2";
    case SourceKind::kPointCloud2:
      return "pointcloud2";
    case SourceKind::kLaserScan:
      return "laserscan";
  }
  return "?";
}

DaemonConfig DaemonConfig::load(const std::filesystem::path& file) {
  return parse(read_file(file), file.string(), file.parent_path());
}

DaemonConfig DaemonConfig::parse(const std::string& yaml, const std::string& source,
                                 const std::filesystem::path& base_dir) {
  std::vector<std::string> problems;
  DaemonConfig c = read(yaml, source, base_dir, problems);
  if (!problems.empty()) throw ConfigErrors(std::move(problems));
  return c;
}

DaemonConfig DaemonConfig::read(const std::string& yaml, const std::string& source,
                                const std::filesystem::path& base_dir, std::vector<std::string>& found) {
  Problems problems(found);
  DaemonConfig c;
  const YamlMap defaults = YamlMap::parse(default_config_yaml(), "built-in config/cellmapd.yaml");
  std::optional<YamlMap> user;
  std::optional<YamlMap> read_root;
  problems.read([&] {
    user = YamlMap::parse(yaml, source);
    read_root.emplace(overlay_on(defaults.node(), user->node(), "", source), "", source);
  });
  if (!read_root) return c;
  YamlMap& root = *read_root;
  problems.read([&] {
    c.cell = root.get<std::string>("cell", c.cell);
    if (c.cell.empty()) root.fail("cell", "must not be empty");
    if (c.cell.find_first_of("*?\\") != std::string::npos)
      root.fail("cell", "must not hold '*', '?' or '\\' (its DDS partition would be a pattern)");
    if (single_line(c.cell, transport::kMaxNameLength) != c.cell)
      root.fail("cell",
                "must be UTF-8 without control characters, at most 128 bytes (subscribers refuse others)");
  });
  problems.read([&] { c.domain = static_cast<int>(root.integer("domain", c.domain, 0, 232)); });
  problems.read([&] { c.state_dir = root.get<std::string>("state_dir", c.state_dir.string()); });
  problems.read([&] { c.sweep_period = root.number("sweep_period", c.sweep_period, 0.0, 3600.0); });
  problems.read([&] { c.status_period = root.number("status_period", c.status_period, 0.05, 3600.0); });
  problems.read([&] {
    c.frame_backlog =
        static_cast<std::size_t>(root.integer("frame_backlog", static_cast<long>(c.frame_backlog), 1, 10000));
  });
  problems.read([&] {
    c.sweep_backlog =
        static_cast<std::size_t>(root.integer("sweep_backlog", static_cast<long>(c.sweep_backlog), 1, 1000));
  });
  problems.read([&] {
    c.delta_depth = static_cast<std::uint32_t>(root.integer("delta_depth", c.delta_depth, 1, 10000));
  });
  problems.read([&] {
    c.log_level = root.get<std::string>("log_level", c.log_level);
    static const std::set<std::string> levels{"trace", "debug", "info", "warn", "error"};
    if (levels.count(c.log_level) == 0)
      root.fail("log_level", "must be one of trace, debug, info, warn, error");
  });

  c.sources = read_sources(root, *user, defaults, c.sweep_period, base_dir, problems);
  problems.read([&] { c.robot = read_daemon_robot(root, base_dir); });
  problems.read([&] { c.pipeline = CellPipelineConfig::from_yaml(root); });
  problems.read([&] { c.security = read_security(root.child("security"), base_dir); });
  problems.read([&] { c.ros2 = read_ros2(root.child("ros2")); });
  problems.read([&] {
    if (!c.sources.empty() && c.simulated() && !c.ros2.joint_states.empty())
      root.child("ros2").fail("joint_states", "poses cameras; the simulated cell moves its robot itself");
  });
  for (const std::string& key : root.unread_keys()) problems.read([&] { root.fail(key, "unknown key"); });
  problems.read([&] { check_ros2_security(c); });
  return c;
}

ConfigErrors::ConfigErrors(std::vector<std::string> problems)
    : Error(joined(problems, "; ")), problems_(std::move(problems)) {}

void ConfigOverrides::apply_to(DaemonConfig& config) const {
  if (domain) config.domain = *domain;
  if (state_dir) config.state_dir = *state_dir;
  if (security) config.security = *security;
}

void check_ros2_security(const DaemonConfig& config) {
  if (config.security && config.uses_ros2()) {
    throw Error(
        "DDS Security is on and the config uses ROS 2 topics (a pointcloud2 or laserscan source, or the ros2 "
        "section), which the cell's permissions cannot protect: turn one of them off (docs/ros2.md)");
  }
}

bool DaemonConfig::uses_ros2() const {
  const bool ros2_source =
      std::any_of(sources.begin(), sources.end(), [](const SourceConfig& s) { return s.is_ros2(); });
  return ros2_source || !ros2.joint_states.empty() || ros2.collision_objects || ros2.markers;
}

}  // namespace cellmap::daemon
