// cellmap: the command-line tool over the cellmap library.
#include <iostream>

#include "cellmap/common/error.hpp"
#include "commands.hpp"

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
  cellmap::cli::add_view_command(app);
  cellmap::cli::add_render_command(app);
  cellmap::cli::add_security_command(app);
  cellmap::cli::add_distance_command(app);
  cellmap::cli::add_sensor_comparison_command(app);
  cellmap::cli::add_paper_figure_command(app);
  cellmap::cli::add_bench_command(app);

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
