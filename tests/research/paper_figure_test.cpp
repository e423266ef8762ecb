// SPDX-License-Identifier: Apache-2.0
#include "cellmap/research/paper_figure.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

namespace cellmap::planning {
namespace {

TEST(PaperFigureTest, KnownDistancesAndConservativeSpheres) {
  const PaperFigure figure = compute_paper_figure(PaperSetup::kRow3);
  ASSERT_EQ(figure.y.size(), 301u);
  // y = -0.8: face to face with an outer box, 0.3 − 0.1 = 0.2.
  EXPECT_NEAR(figure.gjk[70], 0.2, 1e-12);
  // y = 0.1: the turned box's edge at x = 0.4 − 0.1 cos 30° − 0.2 sin 30° faces the cube's face at x = 0.1.
  EXPECT_NEAR(figure.gjk[160], 0.3 - 0.1 * std::cos(M_PI / 6) - 0.2 * std::sin(M_PI / 6), 1e-12);
  // y = 0 on the far left: nearest corner of the first box (0.3, −1.0) to the cube's corner (0.1, −1.4).
  EXPECT_NEAR(figure.gjk[0], std::hypot(0.2, 0.4), 1e-12);
  for (std::size_t k = 0; k < figure.y.size(); ++k) {
    for (const auto& curve : figure.spheres) EXPECT_LE(curve[k], figure.gjk[k] + 1e-12) << figure.y[k];
  }
  // More spheres approximate better where the boxes face each other.
  EXPECT_LT(figure.spheres[0][70], figure.spheres[2][70]);
}

// The paper's setup: y in [-1, 1], six objects, so GJK costs 6 constraints per checkpoint and spheres with
// N = 6 cost 36 in the paper's count (216 counting every sphere pair, as the curves are computed).
TEST(PaperFigureTest, PaperSetupCountsAsThePaperDoes) {
  const PaperFigure figure = compute_paper_figure(PaperSetup::kPaper);
  ASSERT_EQ(figure.y.size(), 201u);
  EXPECT_DOUBLE_EQ(figure.y.front(), -1.0);
  EXPECT_NEAR(figure.y.back(), 1.0, 1e-12);
  EXPECT_EQ(figure.n_rob * figure.n_env, 6);
  // y = -1: face to face with the first (unturned) cuboid, 0.3 − 0.1 = 0.2.
  EXPECT_NEAR(figure.gjk[0], 0.2, 1e-12);
  for (std::size_t k = 0; k < figure.y.size(); ++k) {
    for (const auto& curve : figure.spheres) EXPECT_LE(curve[k], figure.gjk[k] + 1e-12) << figure.y[k];
  }
  const std::string table = paper_constraint_table(figure);
  EXPECT_NE(table.find("| GJK | - | 6 | 1206 |"), std::string::npos) << table;
  EXPECT_NE(table.find("| spheres | 6 | 36 (216) | 7236 (43416) |"), std::string::npos) << table;
}

TEST(PaperFigureTest, OutputsHaveTheContractFormat) {
  const PaperFigure figure = compute_paper_figure(PaperSetup::kRow3);
  std::istringstream csv(paper_figure_csv(figure));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "y;dist_gjk;dist_sphere_n1;dist_sphere_n2;dist_sphere_n6");
  int rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 301);
  const std::string svg = paper_figure_svg(figure);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  std::size_t polylines = 0;
  for (std::size_t at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1))
    ++polylines;
  EXPECT_EQ(polylines, 4u);
  const std::string table = paper_constraint_table(figure);
  EXPECT_NE(table.find("| GJK | - | 3 | 903 |"), std::string::npos) << table;
  EXPECT_NE(table.find("| spheres | 6 | 18 (108) | 5418 (32508) |"), std::string::npos) << table;
}

}  // namespace
}  // namespace cellmap::planning
