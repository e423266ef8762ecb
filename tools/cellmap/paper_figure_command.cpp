// SPDX-License-Identifier: Apache-2.0
// `cellmap paper-figure -o DIR`: the paper's minimum-distance sweep (GJK vs spheres N = 1, 2, 6), in the
// paper's setup and in ours.
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
    const planning::PaperFigure paper = planning::compute_paper_figure(planning::PaperSetup::kPaper);
    const planning::PaperFigure row3 = planning::compute_paper_figure(planning::PaperSetup::kRow3);
    write_file_atomically(out / "paper_figure.csv", planning::paper_figure_csv(paper));
    write_file_atomically(out / "paper_figure.svg", planning::paper_figure_svg(paper));
    write_file_atomically(out / "row3_figure.csv", planning::paper_figure_csv(row3));
    write_file_atomically(out / "row3_figure.svg", planning::paper_figure_svg(row3));
    write_file_atomically(out / "constraints.md", "The paper's setup (6 objects, y from -1 to 1 m):\n\n" +
                                                      planning::paper_constraint_table(paper) +
                                                      "\nOurs (3 boxes, y from -1.5 to 1.5 m):\n\n" +
                                                      planning::paper_constraint_table(row3));
    std::cout << "wrote " << out.string()
              << "/{paper_figure.csv, paper_figure.svg, row3_figure.csv, row3_figure.svg, constraints.md}\n";
  });
}

}  // namespace cellmap::cli
