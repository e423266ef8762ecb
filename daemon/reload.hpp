// SPDX-License-Identifier: Apache-2.0
#pragma once
// SIGHUP: what a running cellmapd takes from its re-read config file.

#include <filesystem>
#include <optional>

#include "cellmap/security/credentials.hpp"

namespace cellmap::daemon {

/// Re-reads `config_file` (empty: the daemon runs on the built-in defaults, which cannot change) and applies
/// `log_level` to the default logger at once. Returns the new `sweep_period` to apply when `sim` (a camera's
/// sweep grouping is fixed when it starts), else nothing. Every other key shapes the map and the versions and
/// applies at restart; the log line says so. DDS Security is the participant's, fixed when it joined: a
/// `security` section that differs from `running_security` (what the daemon started with, from the file or
/// the command line) is logged as a warning naming both, and changes nothing else. A file that does not load
/// changes nothing and is logged with the reason: SIGHUP never stops the daemon.
std::optional<double> reload_config(const std::filesystem::path& config_file, bool sim,
                                    const std::optional<security::Setting>& running_security);

}  // namespace cellmap::daemon
