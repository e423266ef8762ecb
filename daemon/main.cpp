// SPDX-License-Identifier: Apache-2.0
// cellmapd: keeps one cell's collision environment up to date and publishes its versions over DDS.
// The command line and the logger; the daemon itself is daemon.hpp.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "cellmap/common/error.hpp"
#include "config_check.hpp"
#include "daemon.hpp"

namespace {

// `cellmapd --check`: as `nginx -t`, one line `NAME: ok` on stdout, or every problem on stderr and exit 1.
int check_and_report(const std::string& config_file, const std::string& config_name,
                     const cellmap::daemon::ConfigOverrides& overrides) {
  const std::vector<std::string> problems =
      cellmap::daemon::check_config(config_file, config_name, overrides);
  if (problems.empty()) {
    std::cout << config_name << ": ok\n";
    return 0;
  }
  for (const std::string& problem : problems) std::cerr << problem << "\n";
  std::cerr << config_name << ": " << problems.size() << (problems.size() == 1 ? " problem" : " problems")
            << "\n";
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace cellmap::daemon;
  CLI::App app{"cellmapd: keeps a robot cell's collision environment up to date and publishes it over DDS"};
  RunOptions options;
  std::string config_file;
  int domain = 0;
  std::string state_dir;
  app.add_option("--config", config_file, "YAML config (default: built-in defaults, the simulated cell)")
      ->check(CLI::ExistingFile);
  auto* domain_option =
      app.add_option("--domain", domain, "DDS domain id (overrides the config)")->check(CLI::Range(0, 232));
  auto* state_option = app.add_option("--state-dir", state_dir, "state directory (overrides the config)");
  app.add_option("--sweeps", options.max_sweeps, "stop after this many sweeps (0 = run until SIGTERM)");
  std::string security_dir;
  std::string role = "daemon";
  auto* security_option = app.add_option(
      "--security", security_dir, "DDS Security on, with the credentials in DIR (overrides the config)");
  app.add_option("--role", role, "the role whose credentials to use")
      ->check(CLI::IsMember({"daemon", "planner", "robot", "tool"}))
      ->needs(security_option)
      ->capture_default_str();
  bool check = false;
  app.add_flag("--check", check,
               "check the config, its scene, robot, state directory and credentials as a start would, print "
               "`FILE: ok` or every problem found, and exit (0: ok, 1: problems); joins no DDS domain and "
               "opens no sensor");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "cellmapd: " << e.what() << " (see cellmapd --help)\n";
    return 2;
  }
  options.config_file = config_file;
  ConfigOverrides overrides;
  if (*domain_option) overrides.domain = domain;
  if (*state_option) overrides.state_dir = state_dir;
  if (*security_option)
    overrides.security = cellmap::security::Setting{security_dir, cellmap::security::parse_role(role)};
  const std::string config_name = config_file.empty() ? "built-in defaults" : config_file;
  if (check) return check_and_report(config_file, config_name, overrides);

  spdlog::set_default_logger(spdlog::stderr_color_mt("cellmapd"));
  spdlog::set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ %v");
  try {
    // Signals are blocked before any thread starts, so only the main thread takes them.
    const Signals signals;
    DaemonConfig config =
        config_file.empty() ? DaemonConfig::parse("", config_name, ".") : DaemonConfig::load(config_file);
    overrides.apply_to(config);
    spdlog::set_level(spdlog::level::from_str(config.log_level));
    Daemon daemon(std::move(config), options);
    daemon.run(signals);
  } catch (const ConfigErrors& e) {
    for (const std::string& problem : e.problems()) spdlog::critical("{}", problem);
    return 1;
  } catch (const cellmap::Error& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
  return 0;
}
