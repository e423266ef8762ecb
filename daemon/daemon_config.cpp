#include "daemon_config.hpp"

#include <set>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/yaml_map.hpp"

namespace cellmap::daemon {
namespace {

ReconcileOptions reconcile_from_yaml(YamlMap section) {
  ReconcileOptions o;
  o.min_overlap = section.number("min_overlap", o.min_overlap, 0.0, 1.0);
  o.position_tolerance = section.number("position_tolerance", o.position_tolerance, 0.0, 1.0);
  o.rotation_tolerance = section.number("rotation_tolerance", o.rotation_tolerance, 0.0, 3.2);
  o.redundant_tolerance = section.number("redundant_tolerance", o.redundant_tolerance, 0.0, 1.0);
  section.expect_all_read();
  return o;
}

// Lays `overlay` over `base`: maps merge key by key, anything else replaces.
YAML::Node overlay_on(const YAML::Node& base, const YAML::Node& overlay) {
  if (!overlay || overlay.IsNull()) return YAML::Clone(base);
  if (!base.IsDefined() || !base.IsMap() || !overlay.IsMap()) return YAML::Clone(overlay);
  YAML::Node merged = YAML::Clone(base);
  for (const auto& entry : overlay) {
    const std::string key = entry.first.as<std::string>();
    merged[key] = overlay_on(base[key], entry.second);
  }
  return merged;
}

}  // namespace

DaemonConfig DaemonConfig::load(const std::filesystem::path& file) {
  return parse(read_file(file), file.string(), file.parent_path());
}

DaemonConfig DaemonConfig::parse(const std::string& yaml, const std::string& source,
                                 const std::filesystem::path& base_dir) {
  const YamlMap defaults = YamlMap::parse(default_config_yaml(), "built-in config/cellmapd.yaml");
  const YamlMap user = YamlMap::parse(yaml, source);
  YamlMap root(overlay_on(defaults.node(), user.node()), "", source);
  DaemonConfig c;
  c.cell = root.get<std::string>("cell", c.cell);
  if (c.cell.empty()) root.fail("cell", "must not be empty");
  c.domain = static_cast<int>(root.integer("domain", c.domain, 0, 232));
  c.state_dir = root.get<std::string>("state_dir", c.state_dir.string());
  c.sweep_period = root.number("sweep_period", c.sweep_period, 0.0, 3600.0);
  c.status_period = root.number("status_period", c.status_period, 0.05, 3600.0);
  c.delta_depth = static_cast<std::uint32_t>(root.integer("delta_depth", c.delta_depth, 1, 10000));
  c.log_level = root.get<std::string>("log_level", c.log_level);
  static const std::set<std::string> levels{"trace", "debug", "info", "warn", "error"};
  if (levels.count(c.log_level) == 0)
    root.fail("log_level", "must be one of trace, debug, info, warn, error");

  YamlMap source_section = root.child("source");
  c.source.kind = source_section.get<std::string>("kind", c.source.kind);
  if (c.source.kind != "sim")
    source_section.fail("kind", "must be sim (the only source cellmapd wires so far)");
  const std::string scene = source_section.get<std::string>("scene", "");
  if (!scene.empty()) c.source.scene = base_dir / scene;  // an absolute scene path replaces base_dir
  c.source.sensor = source_section.get<std::string>("sensor", c.source.sensor);
  c.source.noise = source_section.get<bool>("noise", c.source.noise);
  source_section.expect_all_read();

  c.occupancy = OccupancyConfig::from_yaml(root.child("occupancy"));
  c.change = ChangeConfig::from_yaml(root.child("change"));
  c.segment = segment_config_from_yaml(root.child("segment"));
  c.reconcile = reconcile_from_yaml(root.child("reconcile"));
  root.expect_all_read();
  return c;
}

}  // namespace cellmap::daemon
