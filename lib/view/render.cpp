// SPDX-License-Identifier: Apache-2.0
#include "cellmap/view/render.hpp"

#include <cairo-svg.h>
#include <cairo.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <ctime>
#include <memory>
#include <sstream>

#include "cellmap/common/error.hpp"

namespace cellmap::view {
namespace {

constexpr double kMargin = 0.06;   // of the panel, on every side
constexpr double kGridStep = 0.5;  // metres between floor grid lines

// Where the camera of a view is: screen right and up, and its viewing direction (all unit, cell frame);
// a perspective camera also has an eye point.
struct Camera {
  Eigen::Vector3d right, up, forward;
  bool perspective = false;
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();

  // Screen coordinates before fitting (u right, v up), and the depth along `forward`.
  [[nodiscard]] Eigen::Vector3d project(const Eigen::Vector3d& p_C) const {
    const Eigen::Vector3d d = p_C - eye;
    const double depth = d.dot(forward);
    if (!perspective) return {d.dot(right), d.dot(up), depth};
    return {d.dot(right) / depth, d.dot(up) / depth, depth};
  }
  [[nodiscard]] bool faces(const Eigen::Vector3d& normal, const Eigen::Vector3d& centre) const {
    return perspective ? normal.dot(eye - centre) > 0 : normal.dot(forward) < 0;
  }
};

struct Bounds {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(1e300);
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-1e300);
  void add(const Eigen::Vector3d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
};

std::array<Eigen::Vector3d, 8> corners(const Box& box) {
  const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
  std::array<Eigen::Vector3d, 8> out;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d sign((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    out[i] = box.center + R * sign.cwiseProduct(box.half_extents);
  }
  return out;
}

// The six faces of a box: corner indices (counter-clockwise seen from outside) and the local normal.
constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                              {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
const Eigen::Vector3d kNormals[6] = {-Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitX(),
                                     -Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitY(),
                                     -Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()};

// A flat piece of a robot's or an obstacle's surface in the cell frame.
struct Facet {
  std::vector<Eigen::Vector3d> corners_C;
  Eigen::Vector3d centre_C = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit; out of a closed solid
  bool two_sided = false;                            // a mesh triangle: seen and lit from either side
  std::array<double, 3> rgb{};
};

constexpr int kRoundSegments = 24;  // around a cylinder or a sphere
constexpr int kSphereRings = 12;    // pole to pole

// The surface of a shape in its frame G as polygons; `closed` is false for meshes (their winding varies).
std::vector<std::vector<Eigen::Vector3d>> surface_in_G(const LinkGeometry& geometry, bool& closed) {
  std::vector<std::vector<Eigen::Vector3d>> out;
  closed = true;
  const auto ring = [](double radius, double z, int i) {
    const double a = 2 * M_PI * i / kRoundSegments;
    return Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), z);
  };
  if (const auto* box = std::get_if<BoxShape>(&geometry)) {
    std::array<Eigen::Vector3d, 8> c;
    for (int i = 0; i < 8; ++i)
      c[i] = Eigen::Vector3d((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1)
                 .cwiseProduct(box->half_extents);
    for (const auto& face : kFaces) out.push_back({c[face[0]], c[face[1]], c[face[2]], c[face[3]]});
  } else if (const auto* cylinder = std::get_if<CylinderShape>(&geometry)) {
    std::vector<Eigen::Vector3d> bottom, top;
    for (int i = 0; i < kRoundSegments; ++i) {
      const double r = cylinder->radius, h = cylinder->half_length;
      out.push_back({ring(r, -h, i), ring(r, -h, i + 1), ring(r, h, i + 1), ring(r, h, i)});
      bottom.push_back(ring(r, -h, i));
      top.push_back(ring(r, h, i));
    }
    out.push_back(bottom);
    out.push_back(top);
  } else if (const auto* sphere = std::get_if<SphereShape>(&geometry)) {
    for (int k = 0; k < kSphereRings; ++k) {
      const double a0 = M_PI * k / kSphereRings - M_PI / 2, a1 = M_PI * (k + 1) / kSphereRings - M_PI / 2;
      const double r0 = sphere->radius * std::cos(a0), r1 = sphere->radius * std::cos(a1);
      const double z0 = sphere->radius * std::sin(a0), z1 = sphere->radius * std::sin(a1);
      for (int i = 0; i < kRoundSegments; ++i) {
        if (k == 0)
          out.push_back({ring(r0, z0, i), ring(r1, z1, i + 1), ring(r1, z1, i)});
        else if (k == kSphereRings - 1)
          out.push_back({ring(r0, z0, i), ring(r0, z0, i + 1), ring(r1, z1, i)});
        else
          out.push_back({ring(r0, z0, i), ring(r0, z0, i + 1), ring(r1, z1, i + 1), ring(r1, z1, i)});
      }
    }
  } else {
    const TriangleMesh& mesh = *std::get<MeshShape>(geometry).mesh;
    mesh.validate("render: robot mesh");
    closed = false;
    for (const Eigen::Vector3i& t : mesh.triangles)
      out.push_back({mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]});
  }
  return out;
}

// The facets of `solid` in the cell frame: centres, unit normals (Newell's method; on a closed solid turned
// away from the shape's centre, since the primitives' polygons are not wound consistently).
std::vector<Facet> facets(const Solid& solid, const std::array<double, 3>& rgb) {
  bool closed = true;
  std::vector<Facet> out;
  for (std::vector<Eigen::Vector3d>& polygon : surface_in_G(solid.geometry, closed)) {
    Facet facet;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      polygon[i] = solid.X_CG * polygon[i];
      facet.centre_C += polygon[i] / static_cast<double>(polygon.size());
    }
    for (std::size_t i = 0; i < polygon.size(); ++i)
      facet.normal += polygon[i].cross(polygon[(i + 1) % polygon.size()]);
    if (facet.normal.norm() > 0) facet.normal.normalize();
    if (closed && facet.normal.dot(facet.centre_C - solid.X_CG.translation()) < 0) facet.normal *= -1;
    facet.two_sided = !closed;
    facet.corners_C = std::move(polygon);
    facet.rgb = rgb;
    out.push_back(std::move(facet));
  }
  return out;
}

// The boxes drawn and, as facets, the overlays: everything a picture's panels fit and draw.
struct Contents {
  std::vector<Box> boxes;
  std::vector<Facet> facets;
  bool translucent_boxes = false;
};

Contents contents_of(const std::vector<Box>& boxes, const Overlays& overlays, bool unknown = true) {
  Contents contents{{}, {}, !overlays.obstacles.empty()};
  for (const Box& box : boxes)
    if (unknown || box.space != BoxSpace::kUnknown) contents.boxes.push_back(box);
  for (const Solid& solid : overlays.obstacles)
    for (Facet& f : facets(solid, obstacle_colour())) contents.facets.push_back(std::move(f));
  for (const Solid& solid : overlays.robot)
    for (Facet& f : facets(solid, robot_colour(solid.carried))) contents.facets.push_back(std::move(f));
  return contents;
}

// Every box corner, every facet corner and the floor (z = 0) under them.
Bounds scene_bounds(const Contents& contents) {
  Bounds bounds;
  const auto add = [&](const Eigen::Vector3d& c) {
    bounds.add(c);
    bounds.add({c.x(), c.y(), 0.0});
  };
  for (const Box& box : contents.boxes)
    for (const Eigen::Vector3d& c : corners(box)) add(c);
  for (const Facet& facet : contents.facets)
    for (const Eigen::Vector3d& c : facet.corners_C) add(c);
  if (contents.boxes.empty() && contents.facets.empty()) {
    bounds.add(Eigen::Vector3d::Zero());
    bounds.add(Eigen::Vector3d::Ones());
  }
  return bounds;
}

Camera camera(View view, const Bounds& bounds) {
  Camera cam;
  switch (view) {
    case View::kTop:
      cam.right = Eigen::Vector3d::UnitX();
      cam.up = Eigen::Vector3d::UnitY();
      cam.forward = -Eigen::Vector3d::UnitZ();
      break;
    case View::kSide:
      cam.right = Eigen::Vector3d::UnitX();
      cam.up = Eigen::Vector3d::UnitZ();
      cam.forward = Eigen::Vector3d::UnitY();
      break;
    case View::kPerspective: {
      const Eigen::Vector3d centre = 0.5 * (bounds.min + bounds.max);
      const double radius = std::max(0.5 * (bounds.max - bounds.min).norm(), 0.1);
      cam.perspective = true;
      cam.eye = centre + 2.6 * radius * Eigen::Vector3d(-0.55, -0.75, 0.62).normalized();
      cam.forward = (centre - cam.eye).normalized();
      cam.right = cam.forward.cross(Eigen::Vector3d::UnitZ()).normalized();
      cam.up = cam.right.cross(cam.forward);
      break;
    }
  }
  return cam;
}

// Screen (u, v) → pixels: the scene's projected extent fitted into the panel, v flipped to point down.
struct Fit {
  double scale = 1, u0 = 0, v0 = 0, cx = 0, cy = 0;
  [[nodiscard]] Eigen::Vector2d pixel(const Eigen::Vector3d& uvd) const {
    return {cx + scale * (uvd.x() - u0), cy - scale * (uvd.y() - v0)};
  }
};

Fit fit(const Camera& cam, const Bounds& bounds, const Panel& panel) {
  double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p((i & 1) ? bounds.max.x() : bounds.min.x(),
                            (i & 2) ? bounds.max.y() : bounds.min.y(),
                            (i & 4) ? bounds.max.z() : bounds.min.z());
    const Eigen::Vector3d uvd = cam.project(p);
    umin = std::min(umin, uvd.x());
    umax = std::max(umax, uvd.x());
    vmin = std::min(vmin, uvd.y());
    vmax = std::max(vmax, uvd.y());
  }
  const double du = std::max(umax - umin, 1e-9);
  const double dv = std::max(vmax - vmin, 1e-9);
  Fit f;
  f.scale = std::min(panel.width * (1 - 2 * kMargin) / du, panel.height * (1 - 2 * kMargin) / dv);
  f.u0 = 0.5 * (umin + umax);
  f.v0 = 0.5 * (vmin + vmax);
  f.cx = panel.x + 0.5 * panel.width;
  f.cy = panel.y + 0.5 * panel.height;
  return f;
}

using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using ContextPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

struct Projection {
  Camera cam;
  Fit fit;
};

Projection projection(const Contents& contents, View view, const Panel& panel) {
  const Bounds bounds = scene_bounds(contents);
  const Camera cam = camera(view, bounds);
  return {cam, fit(cam, bounds, panel)};
}

void draw_grid(cairo_t* cr, const Contents& contents, View view, const Panel& panel) {
  const Bounds bounds = scene_bounds(contents);
  const Projection p = projection(contents, view, panel);
  cairo_set_source_rgb(cr, 0.80, 0.82, 0.85);
  cairo_set_line_width(cr, 1.0);
  const auto line = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const Eigen::Vector2d pa = p.fit.pixel(p.cam.project(a));
    const Eigen::Vector2d pb = p.fit.pixel(p.cam.project(b));
    cairo_move_to(cr, pa.x(), pa.y());
    cairo_line_to(cr, pb.x(), pb.y());
  };
  const double x0 = std::floor(bounds.min.x() / kGridStep) * kGridStep;
  const double y0 = std::floor(bounds.min.y() / kGridStep) * kGridStep;
  const double x1 = std::ceil(bounds.max.x() / kGridStep) * kGridStep;
  const double y1 = std::ceil(bounds.max.y() / kGridStep) * kGridStep;
  for (double x = x0; x <= x1 + 1e-9; x += kGridStep) line({x, y0, 0}, {x, y1, 0});
  for (double y = y0; y <= y1 + 1e-9; y += kGridStep) line({x0, y, 0}, {x1, y, 0});
  cairo_stroke(cr);
}

// The light comes from over the camera's left shoulder.
Eigen::Vector3d light_of(const Camera& cam) {
  return (-cam.forward + 0.6 * cam.up - 0.4 * cam.right).normalized();
}

double depth_of(const Camera& cam, const Eigen::Vector3d& centre) {
  return cam.perspective ? (centre - cam.eye).norm() : cam.project(centre).z();
}

// The faces of `boxes` that face the camera, unsorted.
std::vector<Face> project_faces(const std::vector<Box>& boxes, const Projection& p) {
  const Eigen::Vector3d light = light_of(p.cam);
  std::vector<Face> faces;
  for (const Box& box : boxes) {
    const std::array<Eigen::Vector3d, 8> c = corners(box);
    const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
    for (int f = 0; f < 6; ++f) {
      const Eigen::Vector3d normal = R * kNormals[f];
      const Eigen::Vector3d centre =
          0.25 * (c[kFaces[f][0]] + c[kFaces[f][1]] + c[kFaces[f][2]] + c[kFaces[f][3]]);
      if (!p.cam.faces(normal, centre)) continue;
      Face face;
      face.box_id = box.id;
      face.space = box.space;
      for (int i = 0; i < 4; ++i) face.corners_px[i] = p.fit.pixel(p.cam.project(c[kFaces[f][i]]));
      face.depth = depth_of(p.cam, centre);
      face.shade = 0.45 + 0.55 * std::max(0.0, normal.dot(light));
      faces.push_back(face);
    }
  }
  return faces;
}

// A polygon as painted: pixels, depth (larger = farther), shaded colour; boxes' faces get a dark outline,
// facets of robots and obstacles an outline of their own colour (so tessellation seams do not show).
struct Polygon {
  std::vector<Eigen::Vector2d> corners_px;
  double depth = 0;
  std::array<double, 3> rgb{};
  double alpha = 1;
  bool box_face = false;
  bool unknown = false;  // an unknown box's face: grey, faint, a dashed grey outline
};

std::vector<Polygon> polygons(const Contents& contents, View view, const Panel& panel) {
  const Projection p = projection(contents, view, panel);
  std::vector<Polygon> out;
  for (const Face& face : project_faces(contents.boxes, p)) {
    const bool unknown = face.space == BoxSpace::kUnknown;
    const std::array<double, 3> rgb = unknown ? kUnknownColour : box_colour(face.box_id);
    const double alpha = unknown ? kUnknownAlpha : contents.translucent_boxes ? 0.45 : 1.0;
    out.push_back({{face.corners_px.begin(), face.corners_px.end()},
                   face.depth,
                   {rgb[0] * face.shade, rgb[1] * face.shade, rgb[2] * face.shade},
                   alpha,
                   true,
                   unknown});
  }
  const Eigen::Vector3d light = light_of(p.cam);
  for (const Facet& facet : contents.facets) {
    if (!facet.two_sided && !p.cam.faces(facet.normal, facet.centre_C)) continue;
    const double lit = facet.normal.dot(light);
    const double shade = 0.45 + 0.55 * (facet.two_sided ? std::abs(lit) : std::max(0.0, lit));
    Polygon polygon{{}, depth_of(p.cam, facet.centre_C), {}, 1.0, false, false};
    for (const Eigen::Vector3d& c : facet.corners_C)
      polygon.corners_px.push_back(p.fit.pixel(p.cam.project(c)));
    for (int i = 0; i < 3; ++i) polygon.rgb[i] = facet.rgb[i] * shade;
    out.push_back(std::move(polygon));
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Polygon& a, const Polygon& b) { return a.depth > b.depth; });
  return out;
}

void draw_polygons(cairo_t* cr, const std::vector<Polygon>& polygons) {
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (const Polygon& polygon : polygons) {
    cairo_move_to(cr, polygon.corners_px[0].x(), polygon.corners_px[0].y());
    for (std::size_t i = 1; i < polygon.corners_px.size(); ++i)
      cairo_line_to(cr, polygon.corners_px[i].x(), polygon.corners_px[i].y());
    cairo_close_path(cr);
    cairo_set_source_rgba(cr, polygon.rgb[0], polygon.rgb[1], polygon.rgb[2], polygon.alpha);
    cairo_fill_preserve(cr);
    cairo_set_line_width(cr, polygon.box_face ? 0.8 : 0.5);
    if (polygon.unknown) {
      // Dashed, in a darker grey: the outline says "unknown" even where the faint fill hardly shows.
      static constexpr double kDash[] = {5.0, 3.0};
      cairo_set_dash(cr, kDash, 2, 0);
      cairo_set_source_rgba(cr, 0.42, 0.42, 0.42, 0.9);
    } else if (polygon.box_face) {
      cairo_set_source_rgba(cr, 0.1, 0.1, 0.15, 0.55);
    }
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0);
  }
}

void draw_text(cairo_t* cr, double x, double y, double size, const std::string& text) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_set_source_rgb(cr, 0.15, 0.17, 0.2);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, text.c_str());
}

// A bar of one grid step in an orthographic panel, so distances can be read off.
void draw_scale_bar(cairo_t* cr, const Contents& contents, View view, const Panel& panel) {
  const double length = projection(contents, view, panel).fit.scale * kGridStep;
  const double x = panel.x + 12;
  const double y = panel.y + panel.height - 12;
  cairo_set_source_rgb(cr, 0.15, 0.17, 0.2);
  cairo_set_line_width(cr, 2);
  cairo_move_to(cr, x, y);
  cairo_line_to(cr, x + length, y);
  cairo_stroke(cr);
  std::ostringstream label;
  label << kGridStep << " m";
  draw_text(cr, x + length + 6, y + 4, 11, label.str());
}

void draw_panel(cairo_t* cr, const Contents& contents, View view, const Panel& panel,
                const std::string& name) {
  cairo_save(cr);
  cairo_rectangle(cr, panel.x, panel.y, panel.width, panel.height);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0.78, 0.8, 0.83);
  cairo_set_line_width(cr, 1);
  cairo_stroke_preserve(cr);
  cairo_clip(cr);
  draw_grid(cr, contents, view, panel);
  draw_polygons(cr, polygons(contents, view, panel));
  if (view != View::kPerspective) draw_scale_bar(cr, contents, view, panel);
  draw_text(cr, panel.x + 10, panel.y + 20, 13, name);
  cairo_restore(cr);
}

std::string heading(const Environment& env, bool unknown_drawn) {
  std::ostringstream text;
  text << "cell " << env.cell() << " \xC2\xB7 version " << env.version() << " \xC2\xB7 " << env.boxes().size()
       << " boxes";
  const auto unknown = std::count_if(env.boxes().begin(), env.boxes().end(),
                                     [](const Box& box) { return box.space == BoxSpace::kUnknown; });
  if (unknown > 0)
    text << " (" << unknown << " unknown space" << (unknown_drawn ? ", grey" : ", not drawn") << ")";
  if (env.stamp_ns() > 0) {
    const std::time_t seconds = static_cast<std::time_t>(env.stamp_ns() / 1'000'000'000);
    std::tm utc{};
    gmtime_r(&seconds, &utc);
    char stamp[32];
    std::strftime(stamp, sizeof(stamp), "%Y-%m-%d %H:%M:%S UTC", &utc);
    text << " \xC2\xB7 " << stamp;
  }
  return text.str();
}

void check(cairo_status_t status, const std::filesystem::path& out) {
  if (status != CAIRO_STATUS_SUCCESS)
    throw Error("render: cannot write " + out.string() + ": " + cairo_status_to_string(status));
}

}  // namespace

std::vector<Face> project(const std::vector<Box>& boxes, View view, const Panel& panel) {
  std::vector<Face> faces = project_faces(boxes, projection(contents_of(boxes, {}), view, panel));
  std::stable_sort(faces.begin(), faces.end(),
                   [](const Face& a, const Face& b) { return a.depth > b.depth; });
  return faces;
}

std::array<double, 3> robot_colour(bool carried) {
  // The page's ROBOT_COLOUR 0xf07818 and PAYLOAD_COLOUR 0x8a5a2b.
  return carried ? std::array<double, 3>{0x8a / 255.0, 0x5a / 255.0, 0x2b / 255.0}
                 : std::array<double, 3>{0xf0 / 255.0, 0x78 / 255.0, 0x18 / 255.0};
}

std::array<double, 3> obstacle_colour() {
  return {0.62, 0.63, 0.66};
}

std::array<Panel, 3> layout(const RenderOptions& options) {
  const double top = 44, gap = 12;
  const double w = options.width, h = options.height - top;
  const double left_w = (w - 3 * gap) * 0.4;
  const double half_h = (h - 3 * gap) / 2;
  return {Panel{gap, top + gap, left_w, half_h}, Panel{gap, top + 2 * gap + half_h, left_w, half_h},
          Panel{2 * gap + left_w, top + gap, w - 3 * gap - left_w, h - 2 * gap}};
}

void render(const Environment& env, const std::filesystem::path& out, const RenderOptions& options,
            const Overlays& overlays) {
  const std::string ext = out.extension().string();
  if (ext != ".png" && ext != ".svg")
    throw Error("render: " + out.string() + ": the picture must be a .png or an .svg");
  if (options.width < 200 || options.height < 150)
    throw Error("render: the picture must be at least 200 x 150");
  SurfacePtr surface(ext == ".svg"
                         ? cairo_svg_surface_create(out.c_str(), options.width, options.height)
                         : cairo_image_surface_create(CAIRO_FORMAT_RGB24, options.width, options.height),
                     cairo_surface_destroy);
  check(cairo_surface_status(surface.get()), out);
  ContextPtr cr(cairo_create(surface.get()), cairo_destroy);
  cairo_set_source_rgb(cr.get(), 0.95, 0.96, 0.97);
  cairo_paint(cr.get());
  draw_text(cr.get(), 14, 29, 18, options.title.empty() ? heading(env, options.unknown) : options.title);
  const std::array<Panel, 3> panels = layout(options);
  const Contents contents = contents_of(env.boxes(), overlays, options.unknown);
  draw_panel(cr.get(), contents, View::kTop, panels[0], "top (x right, y up)");
  draw_panel(cr.get(), contents, View::kSide, panels[1], "side (from -y: x right, z up)");
  draw_panel(cr.get(), contents, View::kPerspective, panels[2], "perspective");
  check(cairo_status(cr.get()), out);
  if (ext == ".png") check(cairo_surface_write_to_png(surface.get(), out.c_str()), out);
  cairo_surface_finish(surface.get());
  check(cairo_surface_status(surface.get()), out);
}

}  // namespace cellmap::view
