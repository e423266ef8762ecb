// SPDX-License-Identifier: Apache-2.0
// cellmap: the command-line tool over the cellmap library.
#include <algorithm>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/common/error.hpp"
#include "commands.hpp"

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

std::vector<std::string> subcommand_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; }))
    names.push_back(command->get_name());
  return names;
}

// The first word that is not an option, if it names no subcommand. CLI11 answers --help before it looks at
// the words, so `cellmap nosuch --help` would print the main help and exit 0: a script could not tell a
// missing subcommand from a present one. (The main command's own options, --help and --version, take no
// value, so the first word is the subcommand's name.)
std::optional<std::string> unknown_subcommand(const CLI::App& app, int argc, char** argv) {
  const std::vector<std::string> names = subcommand_names(app);
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") return std::nullopt;
    if (word.empty() || word[0] == '-') continue;
    if (std::find(names.begin(), names.end(), word) != names.end()) return std::nullopt;
    return word;
  }
  return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cellmap: keeps a robot cell's collision environment up to date (tools over the library)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "cellmap 0.1.0");
  cellmap::cli::add_segment_command(app);
  cellmap::cli::add_simulate_command(app);
  cellmap::cli::add_sensors_command(app);
  cellmap::cli::add_echo_command(app);
  cellmap::cli::add_inject_command(app);
  cellmap::cli::add_robot_pose_command(app);
  cellmap::cli::add_status_command(app);
  cellmap::cli::add_view_command(app);
  cellmap::cli::add_render_command(app);
  cellmap::cli::add_security_command(app);
  cellmap::cli::add_distance_command(app);
  cellmap::cli::add_sensor_comparison_command(app);
  cellmap::cli::add_paper_figure_command(app);
  cellmap::cli::add_bench_command(app);

  if (const std::optional<std::string> word = unknown_subcommand(app, argc, argv)) {
    std::cerr << "cellmap: unknown subcommand '" << *word
              << "' (the subcommands: " << joined(subcommand_names(app)) << "; see cellmap --help)\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other failure, so scripts can show it as is.
    std::cerr << "cellmap: " << e.what() << " (see cellmap --help)\n";
    return 2;
  } catch (const cellmap::Error& e) {
    std::cerr << "cellmap: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "cellmap: unexpected failure: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
