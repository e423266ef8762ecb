// SPDX-License-Identifier: Apache-2.0
#pragma once
// Each subcommand of the `cellmap` tool lives in its own file and registers itself on the app through one
// function declared here; main.cpp calls them all. A subcommand reports failure by throwing cellmap::Error
// (main prints "cellmap: <reason>" and exits 1); it prints its results to stdout.

#include <CLI/CLI.hpp>

namespace cellmap::cli {

// void add_<name>_command(CLI::App& app);  -- one line per subcommand, in the order of `cellmap --help`.
void add_segment_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_sensors_command(CLI::App& app);
void add_echo_command(CLI::App& app);
void add_inject_command(CLI::App& app);
void add_robot_pose_command(CLI::App& app);
void add_status_command(CLI::App& app);
void add_view_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_security_command(CLI::App& app);
void add_distance_command(CLI::App& app);
void add_sensor_comparison_command(CLI::App& app);
void add_paper_figure_command(CLI::App& app);
void add_bench_command(CLI::App& app);

}  // namespace cellmap::cli
