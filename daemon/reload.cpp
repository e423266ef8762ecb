#include "reload.hpp"

#include <spdlog/spdlog.h>

#include "cellmap/common/error.hpp"
#include "daemon_config.hpp"

namespace cellmap::daemon {

std::optional<double> reload_config(const std::filesystem::path& config_file, bool sim) {
  if (config_file.empty()) {
    spdlog::info("SIGHUP: running on the built-in defaults (no --config): nothing to reload");
    return std::nullopt;
  }
  try {
    const DaemonConfig fresh = DaemonConfig::load(config_file);
    spdlog::set_level(spdlog::level::from_str(fresh.log_level));
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
