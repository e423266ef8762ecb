// SPDX-License-Identifier: Apache-2.0
#pragma once
// The paper's comparison (section 5.3, fig. 6b): a cube moved along y past a row of boxes; its minimum
// distance by GJK and by bounding spheres with N = 1, 2, 6 per box, and the constraints each method costs.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.
//
// Two scenes (cell frame, metres); the moving cube has half extents 0.1 and centre (0, y, 0.1) in both.
// - kPaper, the paper's setup as far as it states it: y from −1 to 1 in steps of 0.01 (201 checkpoints) past
// a
//   row of n_env = 6 objects, so that GJK needs n_rob · n_env = 6 constraints per checkpoint. Assumed (the
//   paper gives no sizes): six cuboids of half extents (0.1, 0.15, 0.1) centred at x = 0.4, z = 0.1 and
//   y = −1, −0.6, −0.2, 0.2, 0.6, 1, every second one turned 30° about z.
// - kRow3, ours: y from −1.5 to 1.5 (301 checkpoints) past three boxes of half extents (0.1, 0.2, 0.1)
// centred
//   at x = 0.4, z = 0.1 and y = −0.8, 0, 0.8, the middle one turned 30° about z. The cube's face is 0.2 from
//   the outer boxes' faces and 0.1134 from the turned box's nearest edge.

#include <string>
#include <vector>

#include "cellmap/collision/obb.hpp"

namespace cellmap::planning {

/// Which scene a figure is computed on (see above).
enum class PaperSetup { kPaper, kRow3 };

struct PaperFigure final {
  std::vector<double> y;           ///< cube centre y per checkpoint
  std::vector<double> gjk;         ///< exact minimum signed distance (GJK/EPA) per checkpoint
  std::vector<double> spheres[3];  ///< sphere-method minimum distance for N = 1, 2, 6 per checkpoint
  static constexpr int kSphereCounts[3] = {1, 2, 6};
  int n_rob = 1;
  int n_env = 3;
};

/// The setup's row of boxes and the cube at centre y (see above).
[[nodiscard]] std::vector<collision::Obb> paper_row(PaperSetup setup);
[[nodiscard]] collision::Obb paper_cube(double y);

/// Computes the four curves of `setup`. Pure; a few milliseconds.
[[nodiscard]] PaperFigure compute_paper_figure(PaperSetup setup);

/// CSV with header exactly `y;dist_gjk;dist_sphere_n1;dist_sphere_n2;dist_sphere_n6`, one row per checkpoint.
[[nodiscard]] std::string paper_figure_csv(const PaperFigure& figure);
/// A self-contained SVG line plot of the four curves (distance over y), with axes and legend.
[[nodiscard]] std::string paper_figure_svg(const PaperFigure& figure);
/// Markdown table: constraints per checkpoint and over the whole sweep for each method, in both counting
/// conventions for spheres: the paper's (n_rob · n_env · N: its 36 for N = 6 against GJK's 6 read as N per
/// object pair; the paper does not say how it counts) and ours (n_rob · n_env · N², every robot sphere
/// against every environment sphere, what the curves compute). GJK: n_rob · n_env.
[[nodiscard]] std::string paper_constraint_table(const PaperFigure& figure);

}  // namespace cellmap::planning
