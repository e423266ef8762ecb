// SPDX-License-Identifier: Apache-2.0
#pragma once
// A picture of boxes over a simulated scene's true obstacles: an SVG with a top view (x right, y up) and a
// front view (x right, z up), orthographic. Obstacles are filled grey silhouettes, boxes red wireframes.

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/sim/scene.hpp"

namespace cellmap::bench {

/// One orthographic view: which cell axes are drawn right and up, and where.
struct View final {
  int right = 0, up = 1;
  double x0 = 0, y0 = 0, scale = 150;  // pixel position of the cell's minimum corner, pixels per metre
  Eigen::Vector3d min, max;
  [[nodiscard]] double px(const Eigen::Vector3d& p) const { return x0 + scale * (p[right] - min[right]); }
  [[nodiscard]] double py(const Eigen::Vector3d& p) const { return y0 + scale * (max[up] - p[up]); }
};

inline std::string polygon(const View& v, const std::vector<Eigen::Vector3d>& corners, const char* style) {
  std::ostringstream out;
  out << "<polygon points=\"";
  char xy[64];
  for (const Eigen::Vector3d& c : corners) {
    std::snprintf(xy, sizeof xy, "%.1f,%.1f ", v.px(c), v.py(c));
    out << xy;
  }
  out << "\" " << style << "/>\n";
  return out.str();
}

// The six faces of the box with centre, half extents and rotation, each as four corners.
inline std::vector<std::vector<Eigen::Vector3d>> box_faces(const Eigen::Vector3d& c, const Eigen::Vector3d& h,
                                                           const Eigen::Matrix3d& R) {
  std::vector<std::vector<Eigen::Vector3d>> faces;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      std::vector<Eigen::Vector3d> face;
      for (const auto& [u, w] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        Eigen::Vector3d s;
        s[axis] = sign;
        s[(axis + 1) % 3] = u;
        s[(axis + 2) % 3] = w;
        face.push_back(c + R * s.cwiseProduct(h));
      }
      faces.push_back(face);
    }
  }
  return faces;
}

inline std::string obstacle_silhouette(const View& v, const sim::Obstacle& o) {
  const char* style = "fill=\"#b4b4b4\" fill-opacity=\"0.35\" stroke=\"#909090\" stroke-width=\"0.5\"";
  const Eigen::Matrix3d R = o.X_CO.linear();
  const Eigen::Vector3d c = o.X_CO.translation();
  std::string out;
  if (const auto* box = std::get_if<sim::BoxShape>(&o.shape)) {
    for (const auto& face : box_faces(c, box->half_extents, R)) out += polygon(v, face, style);
  } else if (const auto* drum = std::get_if<sim::CylinderShape>(&o.shape)) {
    // A 32-sided prism: caps and side quads, all filled, give the silhouette.
    const int n = 32;
    std::vector<Eigen::Vector3d> top, bottom;
    for (int k = 0; k < n; ++k) {
      const double a = 2 * M_PI * k / n;
      const Eigen::Vector3d r(drum->radius * std::cos(a), drum->radius * std::sin(a), 0);
      top.push_back(c + R * (r + Eigen::Vector3d(0, 0, drum->half_length)));
      bottom.push_back(c + R * (r - Eigen::Vector3d(0, 0, drum->half_length)));
    }
    out += polygon(v, top, style) + polygon(v, bottom, style);
    for (int k = 0; k < n; ++k) {
      out += polygon(v, {top[k], top[(k + 1) % n], bottom[(k + 1) % n], bottom[k]}, style);
    }
  } else {
    const double r = std::get<sim::SphereShape>(o.shape).radius;
    char circle[160];
    std::snprintf(circle, sizeof circle, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"%.1f\" %s/>\n", v.px(c),
                  v.py(c), v.scale * r, style);
    out += circle;
  }
  return out;
}

inline std::string view_panel(const View& v, const sim::Scene& scene, const std::vector<Box>& boxes,
                              const char* title) {
  std::ostringstream out;
  char text[256];
  const Eigen::Vector3d lo = v.min, hi = v.max;
  std::snprintf(text, sizeof text,
                "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"#888\"/>\n"
                "<text x=\"%.1f\" y=\"%.1f\" font-size=\"13\">%s</text>\n",
                v.px(lo), v.py(hi), v.scale * (hi[v.right] - lo[v.right]), v.scale * (hi[v.up] - lo[v.up]),
                v.px(lo), v.py(hi) - 8, title);
  out << text;
  for (const sim::Obstacle& o : scene.obstacles) out << obstacle_silhouette(v, o);
  for (const Box& b : boxes) {
    for (const auto& face : box_faces(b.center, b.half_extents, b.rotation.toRotationMatrix())) {
      out << polygon(v, face, "fill=\"none\" stroke=\"#d62728\" stroke-width=\"1\" stroke-opacity=\"0.8\"");
    }
  }
  return out.str();
}

/// The SVG: the top view over the cell's x–y extent above the front view over its x–z extent.
inline std::string box_picture(const sim::Scene& scene, const std::vector<Box>& boxes,
                               const std::string& caption = "") {
  const double scale = 180, margin = 30;
  View top{0, 1, margin, margin + 10, scale, scene.cell.min, scene.cell.max};
  const Eigen::Vector3d extent = scene.cell.max - scene.cell.min;
  View front{0, 2, margin, top.y0 + scale * extent.y() + 40, scale, scene.cell.min, scene.cell.max};
  const double width = 2 * margin + scale * extent.x();
  const double height = front.y0 + scale * extent.z() + 40;
  std::ostringstream out;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" "
         "fill=\"white\"/>\n";
  out << view_panel(top, scene, boxes, "top view (x right, y up): true obstacles grey, boxes red");
  out << view_panel(front, scene, boxes, "front view (x right, z up)");
  out << "<text x=\"" << margin << "\" y=\"" << height - 12 << "\">" << caption << "</text>\n</svg>\n";
  return out.str();
}

}  // namespace cellmap::bench
