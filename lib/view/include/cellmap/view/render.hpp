// SPDX-License-Identifier: Apache-2.0
#pragma once
// A still picture of a cell's boxes for reports and the README, without a browser: three panels (top, side
// and perspective views) drawn with cairo into a PNG or an SVG, optionally with the robot where it was and
// the true obstacles of a simulated cell under the boxes.
//
// cairo draws in 2D only, so the 3D part is ours, and small: each box's faces that face the camera are
// projected (orthographic for top and side, a pinhole for the perspective) and painted back to front by the
// depth of their centres (the painter's algorithm). That order is exact for boxes that neither intersect
// nor interleave; where boxes intersect (the daemon's boxes may overlap), a face can be painted over where it
// should show: acceptable in a picture, never used for anything else. Robot and obstacle shapes are drawn as
// flat facets (cylinders and spheres tessellated, meshes as their triangles) sorted with the boxes' faces.

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "cellmap/environment/environment.hpp"
#include "cellmap/robot/geometry.hpp"

namespace cellmap::view {

enum class View { kTop, kSide, kPerspective };

/// A rectangle of the picture, pixels (x right, y down).
struct Panel final {
  double x = 0, y = 0, width = 0, height = 0;
};

/// A face of a box as drawn in a panel: its corners in pixels, its depth (larger = farther from the camera)
/// and its brightness (0–1, Lambert shading from a light over the camera's shoulder).
struct Face final {
  std::uint64_t box_id = 0;
  BoxSpace space = BoxSpace::kOccupied;  ///< an unknown box's faces are painted grey and translucent
  std::array<Eigen::Vector2d, 4> corners_px;
  double depth = 0;
  double shade = 0;
};

/// The faces of `boxes` that face the camera of `view`, projected into `panel` and sorted back to front.
/// The scene (the boxes and the floor z = 0 under them) is fitted into the panel with a 6 % margin and a
/// uniform scale, centred: top view x right, y up; side view x right, z up (seen from −y); perspective from
/// the front left, above (−x, −y, +z of the scene's centre).
[[nodiscard]] std::vector<Face> project(const std::vector<Box>& boxes, View view, const Panel& panel);

struct RenderOptions final {
  int width = 1600;  ///< pixels (SVG: points)
  int height = 1000;
  std::string title;  ///< the heading; default: cell, version, box count
  /// Whether unknown boxes (space no sensor has observed) are drawn: in kUnknownColour, translucent
  /// (kUnknownAlpha) with dashed outlines, so the obstacles inside and behind them show. Hidden, they are
  /// left out of the picture and of the scene its panels fit.
  bool unknown = true;
};

/// How opaque an unknown box's faces are painted: faint, since unknown boxes are large and may hold
/// obstacles.
inline constexpr double kUnknownAlpha = 0.3;

/// A solid drawn with the boxes: one of the robot's collision shapes, or a true obstacle of a simulated cell.
struct Solid final {
  Eigen::Isometry3d X_CG = Eigen::Isometry3d::Identity();  ///< the shape's frame G in the cell frame
  LinkGeometry geometry = BoxShape{};
  bool carried = false;  ///< a payload the robot's tool holds (drawn in its own colour)
};

/// What a picture shows besides the boxes; both may be empty.
struct Overlays final {
  std::vector<Solid> robot;      ///< solid, in the robot's colour (the page's)
  std::vector<Solid> obstacles;  ///< solid grey; the boxes are then drawn translucent so both show
};

/// The robot's colour on the page and in pictures (RGB, 0–1); a carried payload's if `carried`.
[[nodiscard]] std::array<double, 3> robot_colour(bool carried);
/// The true obstacles' grey in pictures (RGB, 0–1).
[[nodiscard]] std::array<double, 3> obstacle_colour();

/// The panels of a picture of `options`' size: top view (upper left), side view (lower left), perspective
/// (right, larger).
[[nodiscard]] std::array<Panel, 3> layout(const RenderOptions& options);

/// Draws `env` and `overlays` (three panels, axes, a heading) into `out`: a PNG if its name ends in .png, an
/// SVG if .svg. The scene fitted into the panels holds the boxes and the overlays.
/// @throws Error for another extension, a picture smaller than 200 × 150, a mesh without triangles, or if
/// cairo cannot write the file.
void render(const Environment& env, const std::filesystem::path& out, const RenderOptions& options = {},
            const Overlays& overlays = {});

}  // namespace cellmap::view
