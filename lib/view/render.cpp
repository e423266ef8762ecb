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

// The scene: every box corner and the floor (z = 0) under them.
Bounds scene_bounds(const std::vector<Box>& boxes) {
  Bounds bounds;
  for (const Box& box : boxes) {
    for (const Eigen::Vector3d& c : corners(box)) {
      bounds.add(c);
      bounds.add({c.x(), c.y(), 0.0});
    }
  }
  if (boxes.empty()) {
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

// The six faces of a box: corner indices (counter-clockwise seen from outside) and the local normal.
constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                              {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
const Eigen::Vector3d kNormals[6] = {-Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitX(),
                                     -Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitY(),
                                     -Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()};

using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using ContextPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

struct Projection {
  Camera cam;
  Fit fit;
};

Projection projection(const std::vector<Box>& boxes, View view, const Panel& panel) {
  const Bounds bounds = scene_bounds(boxes);
  const Camera cam = camera(view, bounds);
  return {cam, fit(cam, bounds, panel)};
}

void draw_grid(cairo_t* cr, const std::vector<Box>& boxes, View view, const Panel& panel) {
  const Bounds bounds = scene_bounds(boxes);
  const Projection p = projection(boxes, view, panel);
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

void draw_faces(cairo_t* cr, const std::vector<Face>& faces) {
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_width(cr, 0.8);
  for (const Face& face : faces) {
    const std::array<double, 3> rgb = box_colour(face.box_id);
    cairo_move_to(cr, face.corners_px[0].x(), face.corners_px[0].y());
    for (int i = 1; i < 4; ++i) cairo_line_to(cr, face.corners_px[i].x(), face.corners_px[i].y());
    cairo_close_path(cr);
    cairo_set_source_rgb(cr, rgb[0] * face.shade, rgb[1] * face.shade, rgb[2] * face.shade);
    cairo_fill_preserve(cr);
    cairo_set_source_rgba(cr, 0.1, 0.1, 0.15, 0.55);
    cairo_stroke(cr);
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
void draw_scale_bar(cairo_t* cr, const std::vector<Box>& boxes, View view, const Panel& panel) {
  const double length = projection(boxes, view, panel).fit.scale * kGridStep;
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

void draw_panel(cairo_t* cr, const std::vector<Box>& boxes, View view, const Panel& panel,
                const std::string& name) {
  cairo_save(cr);
  cairo_rectangle(cr, panel.x, panel.y, panel.width, panel.height);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0.78, 0.8, 0.83);
  cairo_set_line_width(cr, 1);
  cairo_stroke_preserve(cr);
  cairo_clip(cr);
  draw_grid(cr, boxes, view, panel);
  draw_faces(cr, project(boxes, view, panel));
  if (view != View::kPerspective) draw_scale_bar(cr, boxes, view, panel);
  draw_text(cr, panel.x + 10, panel.y + 20, 13, name);
  cairo_restore(cr);
}

std::string heading(const Environment& env) {
  std::ostringstream text;
  text << "cell " << env.cell() << " \xC2\xB7 version " << env.version() << " \xC2\xB7 " << env.boxes().size()
       << " boxes";
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
  const Projection p = projection(boxes, view, panel);
  // The light comes from over the camera's left shoulder.
  const Eigen::Vector3d light = (-p.cam.forward + 0.6 * p.cam.up - 0.4 * p.cam.right).normalized();
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
      for (int i = 0; i < 4; ++i) face.corners_px[i] = p.fit.pixel(p.cam.project(c[kFaces[f][i]]));
      face.depth = p.cam.perspective ? (centre - p.cam.eye).norm() : p.cam.project(centre).z();
      face.shade = 0.45 + 0.55 * std::max(0.0, normal.dot(light));
      faces.push_back(face);
    }
  }
  std::stable_sort(faces.begin(), faces.end(),
                   [](const Face& a, const Face& b) { return a.depth > b.depth; });
  return faces;
}

std::array<double, 3> box_colour(std::uint64_t id) {
  // Golden-ratio steps around the hue circle keep neighbouring ids apart; the page uses the same formula.
  const double hue = std::fmod(static_cast<double>(id % 1000003) * 0.618033988749895, 1.0) * 6.0;
  const double s = 0.5, v = 0.9;
  const double c = v * s;
  const double x = c * (1 - std::abs(std::fmod(hue, 2.0) - 1));
  const double m = v - c;
  const int sector = static_cast<int>(hue) % 6;
  static constexpr int kOrder[6][3] = {{0, 1, 2}, {1, 0, 2}, {2, 0, 1}, {2, 1, 0}, {1, 2, 0}, {0, 2, 1}};
  const double parts[3] = {c, x, 0.0};
  return {parts[kOrder[sector][0]] + m, parts[kOrder[sector][1]] + m, parts[kOrder[sector][2]] + m};
}

std::array<Panel, 3> layout(const RenderOptions& options) {
  const double top = 44, gap = 12;
  const double w = options.width, h = options.height - top;
  const double left_w = (w - 3 * gap) * 0.4;
  const double half_h = (h - 3 * gap) / 2;
  return {Panel{gap, top + gap, left_w, half_h}, Panel{gap, top + 2 * gap + half_h, left_w, half_h},
          Panel{2 * gap + left_w, top + gap, w - 3 * gap - left_w, h - 2 * gap}};
}

void render(const Environment& env, const std::filesystem::path& out, const RenderOptions& options) {
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
  draw_text(cr.get(), 14, 29, 18, options.title.empty() ? heading(env) : options.title);
  const std::array<Panel, 3> panels = layout(options);
  draw_panel(cr.get(), env.boxes(), View::kTop, panels[0], "top (x right, y up)");
  draw_panel(cr.get(), env.boxes(), View::kSide, panels[1], "side (from -y: x right, z up)");
  draw_panel(cr.get(), env.boxes(), View::kPerspective, panels[2], "perspective");
  check(cairo_status(cr.get()), out);
  if (ext == ".png") check(cairo_surface_write_to_png(surface.get(), out.c_str()), out);
  cairo_surface_finish(surface.get());
  check(cairo_surface_status(surface.get()), out);
}

}  // namespace cellmap::view
