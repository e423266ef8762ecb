// SPDX-License-Identifier: Apache-2.0
#include "cellmap/research/paper_figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "cellmap/collision/box_distance.hpp"
#include "cellmap/collision/spheres.hpp"
#include "svg_plot.hpp"

namespace cellmap::planning {

using collision::Obb;
using Eigen::Vector3d;

std::vector<Obb> paper_row(PaperSetup setup) {
  const Eigen::Matrix3d turned = Eigen::AngleAxisd(M_PI / 6, Vector3d::UnitZ()).toRotationMatrix();
  if (setup == PaperSetup::kRow3) {
    const Vector3d half(0.1, 0.2, 0.1);
    return {Obb(Vector3d(0.4, -0.8, 0.1), half), Obb(Vector3d(0.4, 0.0, 0.1), half, turned),
            Obb(Vector3d(0.4, 0.8, 0.1), half)};
  }
  std::vector<Obb> row;
  for (int i = 0; i < 6; ++i) {
    const Vector3d centre(0.4, -1.0 + 0.4 * i, 0.1);
    const Vector3d half(0.1, 0.15, 0.1);
    row.push_back(i % 2 == 0 ? Obb(centre, half) : Obb(centre, half, turned));
  }
  return row;
}

Obb paper_cube(double y) {
  return Obb(Vector3d(0.0, y, 0.1), Vector3d(0.1, 0.1, 0.1));
}

PaperFigure compute_paper_figure(PaperSetup setup) {
  PaperFigure figure;
  const std::vector<Obb> row = paper_row(setup);
  const double y_end = setup == PaperSetup::kPaper ? 1.0 : 1.5;
  const int checkpoints = static_cast<int>(std::lround(200 * y_end)) + 1;
  figure.n_env = static_cast<int>(row.size());
  std::vector<std::vector<collision::Sphere>> row_spheres[3];
  for (int m = 0; m < 3; ++m) {
    for (const Obb& box : row)
      row_spheres[m].push_back(collision::sphere_cover(box, PaperFigure::kSphereCounts[m]));
  }
  for (int k = 0; k < checkpoints; ++k) {
    const double y = -y_end + 0.01 * k;
    const Obb cube = paper_cube(y);
    figure.y.push_back(y);
    double gjk = std::numeric_limits<double>::infinity();
    for (const Obb& box : row) gjk = std::min(gjk, collision::signed_distance(cube, box).distance);
    figure.gjk.push_back(gjk);
    for (int m = 0; m < 3; ++m) {
      const auto cube_spheres = collision::sphere_cover(cube, PaperFigure::kSphereCounts[m]);
      double best = std::numeric_limits<double>::infinity();
      for (const auto& spheres : row_spheres[m])
        best = std::min(best, collision::sphere_set_distance(cube_spheres, spheres));
      figure.spheres[m].push_back(best);
    }
  }
  return figure;
}

std::string paper_figure_csv(const PaperFigure& figure) {
  std::ostringstream out;
  out << "y;dist_gjk;dist_sphere_n1;dist_sphere_n2;dist_sphere_n6\n";
  char line[160];
  for (std::size_t k = 0; k < figure.y.size(); ++k) {
    std::snprintf(line, sizeof line, "%.2f;%.9f;%.9f;%.9f;%.9f\n", figure.y[k], figure.gjk[k],
                  figure.spheres[0][k], figure.spheres[1][k], figure.spheres[2][k]);
    out << line;
  }
  return out.str();
}

std::string paper_figure_svg(const PaperFigure& figure) {
  // Plot area in pixels and data ranges; the y range is padded to round 0.05 m steps.
  const double width = 720, height = 420, left = 70, right = 170, top = 30, bottom = 50;
  double lo = *std::min_element(figure.gjk.begin(), figure.gjk.end());
  double hi = *std::max_element(figure.gjk.begin(), figure.gjk.end());
  for (const auto& curve : figure.spheres) {
    lo = std::min(lo, *std::min_element(curve.begin(), curve.end()));
    hi = std::max(hi, *std::max_element(curve.begin(), curve.end()));
  }
  lo = std::floor(lo / 0.05) * 0.05;
  hi = std::ceil(hi / 0.05) * 0.05;
  const double plot_w = width - left - right, plot_h = height - top - bottom;
  const research::PlotAxis px{figure.y.front(), figure.y.back(), left, left + plot_w};
  const research::PlotAxis py{hi, lo, top, top + plot_h};

  research::SvgPlot svg(width, height);
  svg.y_grid(
      py, lo, hi, 0.05, left, left + plot_w, [](double v) { return research::fixed(v, 2); }, "#e4e4e4",
      "#888");
  for (double x = px.v0; x <= px.v1 + 1e-9; x += 0.5) {
    svg.line(px(x), top, px(x), top + plot_h, "#e4e4e4");
    svg.text(px(x), top + plot_h + 18, research::fixed(x, 1), "middle");
  }
  svg.rect(left, top, plot_w, plot_h, "none", "black");
  svg.text(left + plot_w / 2, height - 10, "cube centre y [m]", "middle");
  svg.text(16, top + plot_h / 2, "minimum distance [m]", "middle", 0, -90);
  const std::vector<const std::vector<double>*> curves{&figure.gjk, &figure.spheres[0], &figure.spheres[1],
                                                       &figure.spheres[2]};
  const char* colours[] = {"#000000", "#d62728", "#1f77b4", "#2ca02c"};
  const char* names[] = {"GJK (exact)", "spheres N = 1", "spheres N = 2", "spheres N = 6"};
  for (std::size_t c = 0; c < curves.size(); ++c) {
    std::vector<std::pair<double, double>> points;
    for (std::size_t k = 0; k < figure.y.size(); ++k)
      points.emplace_back(px(figure.y[k]), py((*curves[c])[k]));
    svg.polyline(points, colours[c], c == 0 ? 2.0 : 1.5);
    const double legend_y = top + 10 + 20.0 * c;
    svg.line(left + plot_w + 12, legend_y, left + plot_w + 36, legend_y, colours[c], 2.0);
    svg.text(left + plot_w + 42, legend_y + 4, names[c]);
  }
  return svg.str();
}

std::string paper_constraint_table(const PaperFigure& figure) {
  const std::size_t checkpoints = figure.y.size();
  const std::size_t pairs = static_cast<std::size_t>(figure.n_rob) * figure.n_env;
  std::ostringstream out;
  out << "| method | spheres per box | constraints per checkpoint, paper's count (ours) | constraints for "
      << checkpoints << " checkpoints, paper's count (ours) |\n|---|---|---|---|\n";
  out << "| GJK | - | " << pairs << " | " << pairs * checkpoints << " |\n";
  for (int n : PaperFigure::kSphereCounts) {
    const std::size_t paper = pairs * n, ours = pairs * n * n;
    out << "| spheres | " << n << " | " << paper << " (" << ours << ") | " << paper * checkpoints << " ("
        << ours * checkpoints << ") |\n";
  }
  return out.str();
}

}  // namespace cellmap::planning
