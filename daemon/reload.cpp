// SPDX-License-Identifier: Apache-2.0
#include "reload.hpp"

#include <spdlog/spdlog.h>

#include "cellmap/common/error.hpp"
#include "daemon_config.hpp"

namespace cellmap::daemon {
namespace {

std::string describe(const std::optional<security::Setting>& setting) {
  if (!setting) return "off";
  return fmt::format("{} as {}", setting->directory.string(), security::to_string(setting->role));
}

bool same(const std::optional<security::Setting>& a, const std::optional<security::Setting>& b) {
  if (!a || !b) return !a && !b;
  const auto normal = [](const std::filesystem::path& p) {
    return std::filesystem::absolute(p).lexically_normal();
  };
  return a->role == b->role && normal(a->directory) == normal(b->directory);
}

}  // namespace

std::optional<double> reload_config(const std::filesystem::path& config_file, bool sim,
                                    const std::optional<security::Setting>& running_security) {
  if (config_file.empty()) {
    spdlog::info("SIGHUP: running on the built-in defaults (no --config): nothing to reload");
    return std::nullopt;
  }
  try {
    const DaemonConfig fresh = DaemonConfig::load(config_file);
    spdlog::set_level(spdlog::level::from_str(fresh.log_level));
    if (!same(fresh.security, running_security)) {
      spdlog::warn(
          "SIGHUP: `security` now says {}, but DDS Security stays {} until restart (the participant "
          "joined with it)",
          describe(fresh.security), describe(running_security));
    }
    if (!sim) {
      spdlog::info("SIGHUP: reloaded log_level={} (other keys apply at restart)", fresh.log_level);
      return std::nullopt;
    }
    spdlog::info("SIGHUP: reloaded log_level={} sweep_period={} s (other keys apply at restart)",
                 fresh.log_level, fresh.sweep_period);
    return fresh.sweep_period;
  } catch (const Error& e) {
    spdlog::error("SIGHUP: config not reloaded: {}", e.what());
    return std::nullopt;
  }
}

}  // namespace cellmap::daemon
