// SPDX-License-Identifier: Apache-2.0
#include "cellmap/boxes/volume.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace cellmap {
namespace {

using Polygon = std::vector<Eigen::Vector3d>;  // a convex face, vertices in order around it
using Polyhedron = std::vector<Polygon>;

// Box a's six faces, in the frame of box b (b is then the axis-aligned box ±b.half_extents).
Polyhedron faces_in_frame_of(const Box& a, const Box& b) {
  const Eigen::Matrix3d R_ba = b.rotation.conjugate().toRotationMatrix() * a.rotation.toRotationMatrix();
  const Eigen::Vector3d p_ba = b.rotation.conjugate() * (a.center - b.center);
  const auto corner = [&](int sx, int sy, int sz) {
    return Eigen::Vector3d(p_ba + R_ba * Eigen::Vector3d(sx, sy, sz).cwiseProduct(a.half_extents));
  };
  Polyhedron faces;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      Polygon face;
      for (const auto& [u, v] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        int s[3];
        s[axis] = sign;
        s[(axis + 1) % 3] = u;
        s[(axis + 2) % 3] = v;
        face.push_back(corner(s[0], s[1], s[2]));
      }
      faces.push_back(face);
    }
  }
  return faces;
}

// Keeps the part of `face` where x[axis] * sign <= limit (Sutherland–Hodgman); crossing points are also
// appended to `cut`, the outline of the new face the plane makes.
Polygon clip_face(const Polygon& face, int axis, double sign, double limit,
                  std::vector<Eigen::Vector3d>& cut) {
  Polygon out;
  for (std::size_t i = 0; i < face.size(); ++i) {
    const Eigen::Vector3d& p = face[i];
    const Eigen::Vector3d& q = face[(i + 1) % face.size()];
    const double dp = sign * p[axis] - limit, dq = sign * q[axis] - limit;
    if (dp <= 0) out.push_back(p);
    if ((dp < 0 && dq > 0) || (dp > 0 && dq < 0)) {
      const Eigen::Vector3d x = p + (dp / (dp - dq)) * (q - p);
      out.push_back(x);
      cut.push_back(x);
    } else if (dp == 0) {
      cut.push_back(p);
    }
  }
  return out;
}

// The points of a plane x[axis] = const, ordered by angle around their mean.
Polygon ordered_on_plane(std::vector<Eigen::Vector3d> points, int axis) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  std::sort(points.begin(), points.end(), [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
    return std::atan2(p[v] - mean[v], p[u] - mean[u]) < std::atan2(q[v] - mean[v], q[u] - mean[u]);
  });
  return points;
}

Polyhedron clip(const Polyhedron& body, int axis, double sign, double limit) {
  const auto outside = [&](const Polygon& face) {
    return std::any_of(face.begin(), face.end(),
                       [&](const Eigen::Vector3d& p) { return sign * p[axis] > limit; });
  };
  if (std::none_of(body.begin(), body.end(), outside)) return body;  // a face on the plane is no new face
  Polyhedron out;
  std::vector<Eigen::Vector3d> cut;
  for (const Polygon& face : body) {
    Polygon kept = clip_face(face, axis, sign, limit, cut);
    if (kept.size() >= 3) out.push_back(std::move(kept));
  }
  if (cut.size() >= 3) out.push_back(ordered_on_plane(std::move(cut), axis));
  return out;
}

// Sum of the tetrahedra from an inner point to every face triangle (the body is convex).
double convex_volume(const Polyhedron& body) {
  Eigen::Vector3d inner = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  for (const Polygon& face : body) {
    for (const auto& p : face) inner += p, ++n;
  }
  if (n == 0) return 0.0;
  inner /= static_cast<double>(n);
  double six_volume = 0;
  for (const Polygon& face : body) {
    for (std::size_t i = 1; i + 1 < face.size(); ++i) {
      six_volume += std::abs((face[0] - inner).dot((face[i] - inner).cross(face[i + 1] - inner)));
    }
  }
  return six_volume / 6.0;
}

}  // namespace

double intersection_volume(const Box& a, const Box& b) {
  if (a.volume() <= 0 || b.volume() <= 0) return 0.0;
  Polyhedron body = faces_in_frame_of(a, b);
  for (int axis = 0; axis < 3 && !body.empty(); ++axis) {
    for (double sign : {-1.0, 1.0}) body = clip(body, axis, sign, b.half_extents[axis]);
  }
  return std::min({convex_volume(body), a.volume(), b.volume()});
}

double volume_iou(const Box& a, const Box& b) {
  const double common = intersection_volume(a, b);
  const double both = a.volume() + b.volume() - common;
  return both > 0 ? common / both : 0.0;
}

}  // namespace cellmap
