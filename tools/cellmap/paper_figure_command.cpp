// `cellmap paper-figure -o DIR`: the paper's minimum-distance sweep (GJK vs spheres N = 1, 2, 6).
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.
#include <filesystem>
#include <iostream>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/research/paper_figure.hpp"
#include "commands.hpp"

namespace cellmap::cli {

void add_paper_figure_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "paper-figure",
      "The paper's fig. 6b: minimum distance of a cube passing a row of boxes, GJK vs spheres");
  auto dir = std::make_shared<std::string>();
  command->add_option("-o,--output", *dir, "output folder (created if missing)")->required();
  command->callback([dir] {
    const std::filesystem::path out(*dir);
    std::error_code error;
    std::filesystem::create_directories(out, error);
    if (error) throw Error(*dir + ": cannot create folder (" + error.message() + ")");
    const planning::PaperFigure figure = planning::compute_paper_figure();
    write_file_atomically(out / "paper_figure.csv", planning::paper_figure_csv(figure));
    write_file_atomically(out / "paper_figure.svg", planning::paper_figure_svg(figure));
    write_file_atomically(out / "constraints.md", planning::paper_constraint_table(figure));
    std::cout << "wrote " << (out / "paper_figure.csv").string() << ", "
              << (out / "paper_figure.svg").string() << ", " << (out / "constraints.md").string() << "\n";
  });
}

}  // namespace cellmap::cli
