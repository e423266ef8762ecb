// SPDX-License-Identifier: Apache-2.0
#include "config_check.hpp"

#include <unistd.h>

#include <optional>
#include <variant>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/environment/version_store.hpp"
#include "cellmap/security/credentials.hpp"
#include "cellmap/sensor/sensor_config.hpp"
#include "cellmap/sim/scene.hpp"
#include "simulated_cell.hpp"

namespace cellmap::daemon {
namespace {

// The problems of one config, each prefixed with the config's name and the key it is about.
class Findings {
 public:
  explicit Findings(std::string name) : name_(std::move(name)) {}
  void add(const std::string& key, const std::string& reason) {
    lines_.push_back(name_ + ": " + key + ": " + reason);
  }
  // Runs `check`; its Error becomes a problem under `key` ("" when the message names the key itself).
  template <typename Check>
  bool run(const std::string& key, Check&& check) {
    try {
      check();
      return true;
    } catch (const Error& e) {
      if (key.empty()) {
        lines_.push_back(name_ + ": " + e.what());
      } else {
        add(key, e.what());
      }
      return false;
    }
  }
  std::vector<std::string>& lines() { return lines_; }

 private:
  std::string name_;
  std::vector<std::string> lines_;
};

bool writable_directory(const std::filesystem::path& dir) {
  std::error_code ec;
  return std::filesystem::is_directory(dir, ec) && ::access(dir.c_str(), W_OK | X_OK) == 0;
}

// The daemon creates its state directory when missing (VersionStore), so a missing one is fine if it can be;
// one that holds another cell's versions is refused at start.
void check_state_dir(const std::filesystem::path& dir, const std::string& cell, const std::string& key,
                     Findings& findings) {
  std::error_code ec;
  if (std::filesystem::exists(dir, ec)) {
    if (!std::filesystem::is_directory(dir, ec)) {
      findings.add(key, dir.string() + ": not a directory");
    } else if (!writable_directory(dir)) {
      findings.add(key, dir.string() + ": not writable");
    } else if (const std::optional<std::string> stored = VersionStore::stored_cell(dir);
               stored && *stored != cell) {
      findings.add(key, dir.string() + ": holds the versions of cell '" + *stored + "', not '" + cell + "'");
    }
    return;
  }
  std::filesystem::path parent = std::filesystem::absolute(dir, ec).parent_path();
  while (!parent.empty() && parent != parent.root_path() && !std::filesystem::exists(parent, ec))
    parent = parent.parent_path();
  if (!writable_directory(parent))
    findings.add(key,
                 dir.string() + ": cannot be created (" + parent.string() + " is not a writable directory)");
}

// The simulated scene, loaded and run by the daemon's own SimulatedCell (its sensors, its robot against the
// `robot` section's). A scene that does not load is reported once, under its key.
void check_simulated_cell(const DaemonConfig& config, Findings& findings) {
  const SourceConfig& first = config.sources.front();
  if (!first.scene.empty() &&
      !findings.run(first.key + ".scene", [&] { (void)sim::load_scene(first.scene.string()); })) {
    return;
  }
  findings.run("", [&] { const SimulatedCell cell(config.sources, config.robot); });
}

// Cameras are not opened (a camera that is unplugged at start is a fault the daemon rides out), but their
// settings go through the source's constructor and a replay's directory must be there.
void check_camera(const SourceConfig& source, Findings& findings) {
  findings.run(source.key, [&] { (void)make_depth_source(source.camera); });
  if (const auto* replay = std::get_if<ReplayConfig>(&source.camera.source)) {
    std::error_code ec;
    if (!std::filesystem::is_directory(replay->directory, ec))
      findings.add(source.key + ".replay.directory", replay->directory + ": no such replay directory");
  }
}

void check_credentials(const DaemonConfig& config, const std::string& key, Findings& findings) {
  findings.run(key, [&] {
    const security::Credentials credentials =
        security::check(*config.security, static_cast<std::uint32_t>(config.domain));
    if (credentials.cell != config.cell) {
      throw Error(credentials.files.certificate.string() + ": issued for cell '" + credentials.cell +
                  "', not the config's cell '" + config.cell + "'");
    }
  });
}

}  // namespace

std::vector<std::string> check_config(const std::filesystem::path& file, const std::string& name,
                                      const ConfigOverrides& overrides) {
  Findings findings(name);
  std::string text;
  if (!file.empty() && !findings.run("", [&] { text = read_file(file); })) return findings.lines();
  DaemonConfig config = DaemonConfig::read(
      text, name, file.empty() ? std::filesystem::path(".") : file.parent_path(), findings.lines());
  const bool file_security = config.security.has_value();
  overrides.apply_to(config);
  // The config's own security section was checked against ROS 2 topics by read(); --security was not.
  if (overrides.security && !file_security) findings.run("--security", [&] { check_ros2_security(config); });

  if (!config.sources.empty() && config.simulated()) check_simulated_cell(config, findings);
  for (const SourceConfig& source : config.sources) {
    if (source.is_camera() && !source.is_ros2()) check_camera(source, findings);
  }
  check_state_dir(config.state_dir, config.cell, overrides.state_dir ? "--state-dir" : "state_dir", findings);
  if (config.security) check_credentials(config, overrides.security ? "--security" : "security", findings);
  return std::move(findings.lines());
}

}  // namespace cellmap::daemon
