// SPDX-License-Identifier: Apache-2.0
// Still pictures: the projection against hand-computed answers, and the PNG and SVG cairo writes from it.
#include "cellmap/view/render.hpp"

#include <cairo.h>
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "cellmap/common/atomic_file.hpp"
#include "support/test_support.hpp"
#include "transport/child_process.hpp"

namespace cellmap::view {
namespace {

Box aabb(std::uint64_t id, Eigen::Vector3d center, Eigen::Vector3d half_extents) {
  Box box;
  box.id = id;
  box.center = center;
  box.half_extents = half_extents;
  box.points = 100;
  return box;
}

// One box at (1, 2, 0.5) with half extents (0.5, 0.25, 0.5): its footprint is 1 m × 0.5 m.
const Box kTableBox = aabb(7, {1, 2, 0.5}, {0.5, 0.25, 0.5});

// The corners of a face, in any order and rotation, match `expected` to within `tolerance` pixels.
bool same_quad(const std::array<Eigen::Vector2d, 4>& corners, const std::vector<Eigen::Vector2d>& expected,
               double tolerance) {
  for (const Eigen::Vector2d& e : expected) {
    bool found = false;
    for (const Eigen::Vector2d& c : corners) found = found || (c - e).norm() <= tolerance;
    if (!found) return false;
  }
  return true;
}

TEST(RenderTest, TopViewFitsTheSceneIntoThePanelAndShowsOnlyTopFaces) {
  // Panel 400 × 300; the scene spans 1 × 0.5 m in x, y → scale = min(400 · 0.88 / 1, 300 · 0.88 / 0.5) = 352
  // px/m, centred at (200, 150): x 0.5..1.5 → 24..376 px, y 1.75..2.25 → 238..62 px (y points up).
  const std::vector<Face> faces = project({kTableBox}, View::kTop, Panel{0, 0, 400, 300});
  ASSERT_EQ(faces.size(), 1u);
  EXPECT_EQ(faces[0].box_id, 7u);
  EXPECT_TRUE(same_quad(faces[0].corners_px, {{24, 62}, {376, 62}, {376, 238}, {24, 238}}, 1e-9));
}

TEST(RenderTest, SideViewSeesTheFrontFaceWithZUp) {
  // From −y: u = x (1 m), v = z (0..1 m, the floor is in the scene) → scale = min(352, 264) = 264, centre
  // (200, 150): x → 68..332, z 0..1 → 282..18.
  const std::vector<Face> faces = project({kTableBox}, View::kSide, Panel{0, 0, 400, 300});
  ASSERT_EQ(faces.size(), 1u);
  EXPECT_TRUE(same_quad(faces[0].corners_px, {{68, 18}, {332, 18}, {332, 282}, {68, 282}}, 1e-9));
}

TEST(RenderTest, PerspectiveShowsThreeFacesOfAnAxisAlignedBoxAndPaintsTheNearBoxLast) {
  const Box near = aabb(1, {0, 0, 0.5}, {0.2, 0.2, 0.5});
  const Box far = aabb(2, {2, 2, 0.5}, {0.2, 0.2, 0.5});
  const std::vector<Face> faces = project({near, far}, View::kPerspective, Panel{0, 0, 800, 600});
  ASSERT_EQ(faces.size(), 6u);  // −x, −y and +z of each: the camera is at the front left, above
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(faces[i].box_id, 2u) << i;
  for (std::size_t i = 3; i < 6; ++i) EXPECT_EQ(faces[i].box_id, 1u) << i;
  for (std::size_t i = 1; i < faces.size(); ++i) EXPECT_LE(faces[i].depth, faces[i - 1].depth);
}

TEST(RenderTest, TopViewPaintsTheHigherBoxOverTheLowerOne) {
  const Box low = aabb(1, {0, 0, 0.1}, {1.0, 1.0, 0.1});
  const Box high = aabb(2, {0, 0, 0.3}, {0.2, 0.2, 0.1});
  const std::vector<Face> faces = project({high, low}, View::kTop, Panel{0, 0, 400, 400});
  ASSERT_EQ(faces.size(), 2u);
  EXPECT_EQ(faces.front().box_id, 1u);
  EXPECT_EQ(faces.back().box_id, 2u);
}

TEST(RenderTest, ColoursDependOnTheIdOnly) {
  EXPECT_EQ(box_colour(45), box_colour(45));
  EXPECT_NE(box_colour(45), box_colour(46));
  for (double c : box_colour(12345)) {
    EXPECT_GE(c, 0.0);
    EXPECT_LE(c, 1.0);
  }
}

std::array<std::uint8_t, 3> pixel(cairo_surface_t* image, int x, int y) {
  const unsigned char* row = cairo_image_surface_get_data(image) + y * cairo_image_surface_get_stride(image);
  const std::uint32_t argb = reinterpret_cast<const std::uint32_t*>(row)[x];
  return {static_cast<std::uint8_t>(argb >> 16), static_cast<std::uint8_t>(argb >> 8),
          static_cast<std::uint8_t>(argb)};
}

TEST(RenderTest, PngShowsTheBoxWhereItsTopFaceProjects) {
  test::TempDir dir;
  const Box low = aabb(3, {2.5, 1.0, 0.2}, {0.3, 0.3, 0.2});
  const Environment env("cell-1", 4, 0, {kTableBox, low});
  const RenderOptions options;
  render(env, dir.path() / "cell.png", options);
  cairo_surface_t* image = cairo_image_surface_create_from_png((dir.path() / "cell.png").c_str());
  ASSERT_EQ(cairo_surface_status(image), CAIRO_STATUS_SUCCESS);
  EXPECT_EQ(cairo_image_surface_get_width(image), options.width);
  EXPECT_EQ(cairo_image_surface_get_height(image), options.height);
  const Panel top = layout(options)[0];
  const std::vector<Face> faces = project(env.boxes(), View::kTop, top);
  for (const Face& face : faces) {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& c : face.corners_px) centre += c / 4;
    const auto rgb = pixel(image, static_cast<int>(centre.x()), static_cast<int>(centre.y()));
    const std::array<double, 3> colour = box_colour(face.box_id);
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(rgb[i], 255 * colour[i] * face.shade, 2.0) << "box " << face.box_id << " channel " << i;
  }
  // The panel's corner, away from boxes and grid, is the white background.
  const auto background =
      pixel(image, static_cast<int>(top.x + 3), static_cast<int>(top.y + top.height - 30));
  EXPECT_EQ(background, (std::array<std::uint8_t, 3>{255, 255, 255}));
  cairo_surface_destroy(image);
}

// The pixel of p_C in the top panel of a default picture whose scene spans x ∈ [x0, x1], y ∈ [y0, y1]: the
// extent fitted with a 6 % margin at a uniform scale, centred (layout() and project()'s contract).
Eigen::Vector2d top_pixel(const Eigen::Vector3d& p_C, double x0, double x1, double y0, double y1) {
  const Panel top = layout(RenderOptions{})[0];
  const double scale = std::min(top.width * 0.88 / (x1 - x0), top.height * 0.88 / (y1 - y0));
  return {top.x + top.width / 2 + scale * (p_C.x() - (x0 + x1) / 2),
          top.y + top.height / 2 - scale * (p_C.y() - (y0 + y1) / 2)};
}

// Faces turned straight up, lit from over the top view's camera's left shoulder: (-0.4, 0.6, 1) normalised.
const double kTopShade = 0.45 + 0.55 / std::sqrt(0.16 + 0.36 + 1.0);

void expect_colour(cairo_surface_t* image, const Eigen::Vector2d& at, const std::array<double, 3>& rgb,
                   const std::string& what) {
  const auto got = pixel(image, static_cast<int>(at.x()), static_cast<int>(at.y()));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], 255 * rgb[i], 2.5) << what << " channel " << i;
}

TEST(RenderTest, RobotShapesAreDrawnInTheRobotColourWhereTheyStand) {
  test::TempDir dir;
  Overlays overlays;
  // A column (cylinder r 0.2 m, 1 m high) at (3, 2) and, lying at z 0.2, a triangle of a mesh wound
  // clockwise seen from above: meshes are drawn from both sides.
  overlays.robot.push_back({Eigen::Isometry3d(Eigen::Translation3d(3, 2, 0.5)), CylinderShape{0.2, 0.5}});
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->vertices = {{2.0, 1.8, 0.2}, {2.0, 2.2, 0.2}, {2.4, 1.8, 0.2}};
  mesh->triangles = {{0, 1, 2}};
  overlays.robot.push_back({Eigen::Isometry3d::Identity(), MeshShape{mesh}, true});
  render(Environment("cell-1", 1, 0, {kTableBox}), dir.path() / "robot.png", {}, overlays);
  cairo_surface_t* image = cairo_image_surface_create_from_png((dir.path() / "robot.png").c_str());
  ASSERT_EQ(cairo_surface_status(image), CAIRO_STATUS_SUCCESS);
  // The scene spans the box (x 0.5..1.5, y 1.75..2.25) and the column (x 2.8..3.2).
  const auto at = [](double x, double y) { return top_pixel({x, y, 0}, 0.5, 3.2, 1.75, 2.25); };
  const auto shaded = [](std::array<double, 3> rgb) {
    for (double& c : rgb) c *= kTopShade;
    return rgb;
  };
  expect_colour(image, at(3.0, 2.0), shaded(robot_colour(false)), "the column's top");
  expect_colour(image, at(2.1333, 1.9333), shaded(robot_colour(true)), "the carried triangle");
  expect_colour(image, at(1.0, 2.1), shaded(box_colour(kTableBox.id)), "the box, opaque without obstacles");
  cairo_surface_destroy(image);
}

TEST(RenderTest, TrueObstaclesShowThroughTranslucentBoxes) {
  test::TempDir dir;
  Overlays overlays;
  overlays.obstacles.push_back(
      {Eigen::Isometry3d(Eigen::Translation3d(1, 2, 0.4)), BoxShape{{0.3, 0.2, 0.4}}});
  render(Environment("cell-1", 1, 0, {kTableBox}), dir.path() / "truth.png", {}, overlays);
  cairo_surface_t* image = cairo_image_surface_create_from_png((dir.path() / "truth.png").c_str());
  ASSERT_EQ(cairo_surface_status(image), CAIRO_STATUS_SUCCESS);
  const auto at = [](double x, double y) { return top_pixel({x, y, 0}, 0.5, 1.5, 1.75, 2.25); };
  const std::array<double, 3> box = box_colour(kTableBox.id);
  const std::array<double, 3> grey = obstacle_colour();
  std::array<double, 3> over_obstacle{}, over_floor{};
  for (int i = 0; i < 3; ++i) {
    over_obstacle[i] = 0.45 * box[i] * kTopShade + 0.55 * grey[i] * kTopShade;
    over_floor[i] = 0.45 * box[i] * kTopShade + 0.55;  // the panel's white under the box
  }
  expect_colour(image, at(1.1, 2.1), over_obstacle, "the box over the obstacle's top");
  expect_colour(image, at(1.4, 2.1), over_floor, "the box beside the obstacle");
  cairo_surface_destroy(image);
}

// An unknown box (x 2..3) between two obstacle boxes (x 0..1 and 4..5), holding a small obstacle box: the
// scene spans x 0..5, y 0..1, z 0..1 whether the unknown box is drawn or not, so both pictures share pixels.
std::vector<Box> unknown_between_obstacles() {
  Box unknown = aabb(2, {2.5, 0.5, 0.5}, {0.5, 0.5, 0.5});
  unknown.space = BoxSpace::kUnknown;
  return {aabb(1, {0.5, 0.5, 0.5}, {0.5, 0.5, 0.5}), unknown, aabb(3, {2.5, 0.5, 0.2}, {0.2, 0.2, 0.2}),
          aabb(4, {4.5, 0.5, 0.5}, {0.5, 0.5, 0.5})};
}

// Where the top panel shows (x, y) of unknown_between_obstacles(): clear of the 0.5 m grid lines.
Eigen::Vector2d top_of_scene(double x, double y) {
  return top_pixel({x, y, 0}, 0, 5, 0, 1);
}

std::array<double, 3> shaded(std::array<double, 3> rgb, double shade) {
  for (double& c : rgb) c *= shade;
  return rgb;
}

TEST(RenderTest, UnknownBoxesAreFaintGreyOverWhatTheyHoldAndLeftOutWhenHidden) {
  test::TempDir dir;
  const Environment env("cell-1", 1, 0, unknown_between_obstacles());
  render(env, dir.path() / "shown.png");
  RenderOptions hide;
  hide.unknown = false;
  render(env, dir.path() / "hidden.png", hide);
  cairo_surface_t* shown = cairo_image_surface_create_from_png((dir.path() / "shown.png").c_str());
  cairo_surface_t* hidden = cairo_image_surface_create_from_png((dir.path() / "hidden.png").c_str());
  ASSERT_EQ(cairo_surface_status(shown), CAIRO_STATUS_SUCCESS);
  ASSERT_EQ(cairo_surface_status(hidden), CAIRO_STATUS_SUCCESS);
  const std::array<double, 3> grey = shaded(kUnknownColour, kTopShade);
  const std::array<double, 3> held = shaded(box_colour(3), kTopShade);
  std::array<double, 3> grey_over_white{}, grey_over_held{};
  for (int i = 0; i < 3; ++i) {
    grey_over_white[i] = kUnknownAlpha * grey[i] + (1 - kUnknownAlpha);
    grey_over_held[i] = kUnknownAlpha * grey[i] + (1 - kUnknownAlpha) * held[i];
  }
  // Shown: a neutral grey over the white panel, and the obstacle inside seen through it in its own hue.
  expect_colour(shown, top_of_scene(2.85, 0.2), grey_over_white, "the unknown box's top");
  expect_colour(shown, top_of_scene(2.4, 0.6), grey_over_held,
                "the obstacle inside, through the unknown box");
  expect_colour(shown, top_of_scene(0.3, 0.2), shaded(box_colour(1), kTopShade), "an obstacle box");
  // Hidden: the panel's white where the unknown box was, the obstacle inside as it is.
  expect_colour(hidden, top_of_scene(2.85, 0.2), {1, 1, 1}, "where the unknown box was");
  expect_colour(hidden, top_of_scene(2.4, 0.6), held, "the obstacle that was inside");
  expect_colour(hidden, top_of_scene(0.3, 0.2), shaded(box_colour(1), kTopShade), "an obstacle box");
  cairo_surface_destroy(shown);
  cairo_surface_destroy(hidden);
}

TEST(RenderTest, UnknownFacesAreProjectedWithTheirSpace) {
  const std::vector<Face> faces = project(unknown_between_obstacles(), View::kTop, Panel{0, 0, 500, 100});
  ASSERT_EQ(faces.size(), 4u);
  for (const Face& face : faces) EXPECT_EQ(face.space == BoxSpace::kUnknown, face.box_id == 2) << face.box_id;
}

// Every path of the SVG as its list of points ("M x y L x y ... Z").
std::vector<std::vector<Eigen::Vector2d>> svg_paths(const std::string& svg) {
  std::vector<std::vector<Eigen::Vector2d>> paths;
  const std::regex path_re(R"re(<path [^>]*d="([^"]*)")re");
  const std::regex point_re(R"re([ML] (-?[0-9.]+) (-?[0-9.]+))re");
  for (std::sregex_iterator p(svg.begin(), svg.end(), path_re), end; p != end; ++p) {
    const std::string d = (*p)[1];
    std::vector<Eigen::Vector2d> points;
    for (std::sregex_iterator q(d.begin(), d.end(), point_re); q != end; ++q)
      points.emplace_back(std::stod((*q)[1]), std::stod((*q)[2]));
    paths.push_back(points);
  }
  return paths;
}

TEST(RenderTest, SvgHoldsTheTopFaceAsAPolygon) {
  test::TempDir dir;
  render(Environment("cell-1", 1, 0, {kTableBox}), dir.path() / "cell.svg");
  // Default 1600 × 1000: the top panel is x 12..637.6, y 56..516 (layout()); the box's 1 × 0.5 m footprint
  // fills it at min(625.6 · 0.88 / 1, 460 · 0.88 / 0.5) = 550.528 px/m around (324.8, 286):
  // x 49.536..600.064, y 148.368..423.632.
  const std::vector<Eigen::Vector2d> expected{
      {49.536, 148.368}, {600.064, 148.368}, {600.064, 423.632}, {49.536, 423.632}};
  int matches = 0;
  for (const std::vector<Eigen::Vector2d>& path : svg_paths(read_file(dir.path() / "cell.svg"))) {
    if (path.size() < 4) continue;
    const std::array<Eigen::Vector2d, 4> quad{path[0], path[1], path[2], path[3]};
    if (same_quad(quad, expected, 0.01)) ++matches;
  }
  EXPECT_GE(matches, 1);  // the fill (and its outline)
}

TEST(RenderTest, RefusesOtherFormats) {
  test::TempDir dir;
  EXPECT_NE(test::error_of([&] {
              render(Environment("c", 1, 0, {}), dir.path() / "cell.jpg");
            }).find("must be a .png or an .svg"),
            std::string::npos);
}

TEST(RenderTest, CommandDrawsABoxesFile) {
  test::TempDir dir;
  const std::filesystem::path boxes = dir.path() / "boxes.json";
  write_box_file(boxes, BoxSet{5, "cell", {kTableBox}});
  const std::filesystem::path png = dir.path() / "out.png";
  test::ChildProcess tool({CELLMAP_TOOL, "render", boxes.string(), "-o", png.string()});
  const std::string line = tool.read_line(std::chrono::seconds(60)).value_or("");
  EXPECT_EQ(tool.wait(), 0);
  EXPECT_EQ(line, "wrote " + png.string() + ": cell boxes, version 5, 1 boxes");
  EXPECT_EQ(read_file(png).substr(1, 3), "PNG");

  test::ChildProcess bad({CELLMAP_TOOL, "render", boxes.string(), "-o", (dir.path() / "out.gif").string()});
  const int status = bad.wait();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << status;
}

// The number of pixels within 2 of `rgb` (0–1) in every channel in the rectangle of `image` between the
// pixels `a` and `b`.
int pixels_of_colour(cairo_surface_t* image, const std::array<double, 3>& rgb, const Eigen::Vector2d& a,
                     const Eigen::Vector2d& b) {
  int count = 0;
  for (int y = int(std::min(a.y(), b.y())); y <= int(std::max(a.y(), b.y())); ++y) {
    for (int x = int(std::min(a.x(), b.x())); x <= int(std::max(a.x(), b.x())); ++x) {
      const auto got = pixel(image, x, y);
      bool near = true;
      for (int i = 0; i < 3; ++i) near = near && std::abs(got[i] - 255 * rgb[i]) <= 2.0;
      count += near ? 1 : 0;
    }
  }
  return count;
}

TEST(RenderTest, CommandDrawsUnknownSpaceGreyUnlessHidden) {
  test::TempDir dir;
  const std::filesystem::path boxes = dir.path() / "boxes.json";
  write_box_file(boxes, BoxSet{6, "cell", unknown_between_obstacles()});
  const auto run = [&](const std::string& name, std::vector<std::string> extra) {
    const std::filesystem::path png = dir.path() / name;
    std::vector<std::string> argv{CELLMAP_TOOL, "render", boxes.string(), "-o", png.string()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    test::ChildProcess tool(argv);
    const std::string line = tool.read_line(std::chrono::seconds(60)).value_or("");
    EXPECT_EQ(tool.wait(), 0);
    return std::make_pair(line, png);
  };
  const auto [shown_line, shown_png] = run("shown.png", {});
  EXPECT_EQ(shown_line, "wrote " + shown_png.string() + ": cell boxes, version 6, 4 boxes (1 unknown)");
  const auto [hidden_line, hidden_png] = run("hidden.png", {"--unknown", "hide"});
  EXPECT_EQ(hidden_line,
            "wrote " + hidden_png.string() + ": cell boxes, version 6, 4 boxes (1 unknown, not drawn)");

  // The unknown box's top in the top view (x 2..3, y 0..1), faint grey over the white panel where the
  // obstacle inside is not: there when shown, nowhere when hidden.
  std::array<double, 3> top_grey{};
  for (int i = 0; i < 3; ++i)
    top_grey[i] = kUnknownAlpha * kUnknownColour[i] * kTopShade + (1 - kUnknownAlpha);
  cairo_surface_t* shown = cairo_image_surface_create_from_png(shown_png.c_str());
  cairo_surface_t* hidden = cairo_image_surface_create_from_png(hidden_png.c_str());
  ASSERT_EQ(cairo_surface_status(shown), CAIRO_STATUS_SUCCESS);
  ASSERT_EQ(cairo_surface_status(hidden), CAIRO_STATUS_SUCCESS);
  expect_colour(shown, top_of_scene(2.85, 0.2), top_grey, "the unknown box's top, shown");
  expect_colour(hidden, top_of_scene(2.85, 0.2), {1, 1, 1}, "where the unknown box is, hidden");
  const Eigen::Vector2d from = top_of_scene(2.02, 0.02), to = top_of_scene(2.98, 0.98);
  const int grey_shown = pixels_of_colour(shown, top_grey, from, to);
  const int grey_hidden = pixels_of_colour(hidden, top_grey, from, to);
  // About 110 × 110 pixels, less the obstacle inside (a sixth), the grid lines and the dashed outline.
  EXPECT_GT(grey_shown, 7000);
  EXPECT_EQ(grey_hidden, 0);
  cairo_surface_destroy(shown);
  cairo_surface_destroy(hidden);

  test::ChildProcess bad(
      {CELLMAP_TOOL, "render", boxes.string(), "--unknown", "dim", "-o", (dir.path() / "x.png").string()});
  const int status = bad.wait();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << status;
}

}  // namespace
}  // namespace cellmap::view
