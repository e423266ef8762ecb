// SPDX-License-Identifier: Apache-2.0
#pragma once
// `cellmapd --check`: what would stop the daemon at start, found without starting it.

#include <filesystem>
#include <string>
#include <vector>

#include "daemon_config.hpp"

namespace cellmap::daemon {

/// Checks a config as cellmapd's start would use it, short of joining DDS and opening sensors, and goes on
/// past each problem to find the next: the config's keys (DaemonConfig::read, with `overrides` laid over
/// it), the robot's URDF and meshes (read with the `robot` section), the simulated scene with its sensors
/// and robot (the daemon's own SimulatedCell), each camera's settings and replay directory, the state
/// directory (there or creatable, not another cell's) and the DDS Security credentials (security::check,
/// issued for the config's cell).
/// `file` empty: the built-in defaults, named `name` in messages.
/// @return every problem, one line each ("<config>: <key>: <reason>"); empty if the daemon would start.
[[nodiscard]] std::vector<std::string> check_config(const std::filesystem::path& file,
                                                    const std::string& name,
                                                    const ConfigOverrides& overrides);

}  // namespace cellmap::daemon
