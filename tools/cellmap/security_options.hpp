// SPDX-License-Identifier: Apache-2.0
#pragma once
// `--security DIR --role R`, the same on every subcommand that joins a DDS domain.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "cellmap/security/credentials.hpp"

namespace cellmap::cli {

struct SecurityOptions {
  std::string directory;  ///< empty: DDS Security off
  std::string role;

  /// The participant's setting; nullopt without --security.
  [[nodiscard]] std::optional<security::Setting> setting() const {
    if (directory.empty()) return std::nullopt;
    return security::Setting{directory, security::parse_role(role)};
  }
};

/// Adds --security and --role (default `role`) to `command`.
inline void add_security_options(CLI::App* command, SecurityOptions& options, security::Role role) {
  options.role = security::to_string(role);
  CLI::Option* directory =
      command->add_option("--security", options.directory,
                          "DDS Security on, with the credentials in DIR (cellmap security init)");
  command->add_option("--role", options.role, "the role whose credentials to use")
      ->check(CLI::IsMember({"daemon", "planner", "robot", "tool"}))
      ->needs(directory)
      ->capture_default_str();
}

}  // namespace cellmap::cli
