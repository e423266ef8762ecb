// SPDX-License-Identifier: Apache-2.0
#include "epa.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "gjk.hpp"
#include "signed_distance.hpp"

namespace cellmap::collision {
namespace {

using Eigen::Vector3d;

// Directions that leave the span of GJK's final simplex (a point, segment or triangle through the origin).
std::vector<Vector3d> directions_out_of_span(const Simplex& simplex) {
  if (simplex.n == 1) {
    std::vector<Vector3d> directions;
    for (int k = 0; k < 3; ++k) directions.insert(directions.end(), {Vector3d::Unit(k), -Vector3d::Unit(k)});
    return directions;
  }
  if (simplex.n == 2) {
    const Vector3d d = (simplex.v[1].w - simplex.v[0].w).normalized();
    int k = 0;
    d.cwiseAbs().minCoeff(&k);
    const Vector3d e1 = d.cross(Vector3d::Unit(k)).normalized();
    const Vector3d e2 = d.cross(e1);
    return {e1, -e1, e2, -e2};
  }
  const Vector3d n = (simplex.v[1].w - simplex.v[0].w).cross(simplex.v[2].w - simplex.v[0].w).normalized();
  const double side = n.dot(simplex.v[0].w) > 0.0 ? -1.0 : 1.0;  // towards the origin first
  return {side * n, -side * n};
}

// Distance of w from the affine span of the simplex.
double distance_from_span(const Simplex& simplex, const Vector3d& w) {
  const Vector3d r = w - simplex.v[0].w;
  if (simplex.n == 1) return r.norm();
  if (simplex.n == 2) {
    const Vector3d d = (simplex.v[1].w - simplex.v[0].w).normalized();
    return (r - r.dot(d) * d).norm();
  }
  const Vector3d n = (simplex.v[1].w - simplex.v[0].w).cross(simplex.v[2].w - simplex.v[0].w).normalized();
  return std::abs(n.dot(r));
}

// GJK may stop on a segment or triangle through the origin (inside D): grows it to a tetrahedron by support
// points off its span. False if D is flat (the depth is then 0).
bool grow_to_tetrahedron(const MinkowskiSupport& support, double scale, Simplex* simplex) {
  const double flat = 1e-12 * scale;
  for (int attempt = 0; simplex->n < 4 && attempt < 3; ++attempt) {
    bool grown = false;
    for (const Vector3d& direction : directions_out_of_span(*simplex)) {
      const SupportVertex w = support(direction);
      if (distance_from_span(*simplex, w.w) > flat) {
        simplex->v[simplex->n++] = w;
        grown = true;
        break;
      }
    }
    if (!grown) break;
  }
  return simplex->n == 4;
}

struct Face {
  std::array<int, 3> v;
  Vector3d normal;  // unit, outward
  double distance;  // of the face's plane from the origin (>= 0 while the origin is inside)
};

// The polytope around the origin, growing inside D.
struct Polytope {
  std::vector<SupportVertex> vertices;
  std::vector<Face> faces;

  // Adds the face (i0, i1, i2), normal by the right-hand rule; false if degenerate.
  bool add_face(int i0, int i1, int i2) {
    const Vector3d n = (vertices[i1].w - vertices[i0].w).cross(vertices[i2].w - vertices[i0].w);
    const double length = n.norm();
    if (!(length > 0.0)) return false;
    faces.push_back({{i0, i1, i2}, n / length, n.dot(vertices[i0].w) / length});
    return true;
  }

  [[nodiscard]] bool knows(const SupportVertex& w) const {
    return std::any_of(vertices.begin(), vertices.end(),
                       [&](const SupportVertex& v) { return v.id == w.id; });
  }

  [[nodiscard]] const Face* closest_face() const {
    const auto it = std::min_element(faces.begin(), faces.end(),
                                     [](const Face& f, const Face& g) { return f.distance < g.distance; });
    return it == faces.end() ? nullptr : &*it;
  }

  // Removes the faces w sees and stitches their horizon to w.
  void expand(const SupportVertex& w) {
    const int wi = static_cast<int>(vertices.size());
    vertices.push_back(w);
    std::vector<std::array<int, 2>> horizon;
    std::vector<Face> kept;
    for (const Face& face : faces) {
      if (face.normal.dot(w.w - vertices[face.v[0]].w) <= 0.0) {
        kept.push_back(face);
        continue;
      }
      for (int e = 0; e < 3; ++e) {
        const std::array<int, 2> edge{face.v[e], face.v[(e + 1) % 3]};
        const auto twin = std::find(horizon.begin(), horizon.end(), std::array<int, 2>{edge[1], edge[0]});
        if (twin != horizon.end()) {
          horizon.erase(twin);
        } else {
          horizon.push_back(edge);
        }
      }
    }
    faces.swap(kept);
    for (const auto& edge : horizon) add_face(edge[0], edge[1], wi);
  }
};

// The tetrahedron's faces, oriented outwards.
Polytope initial_polytope(const Simplex& simplex) {
  Polytope polytope;
  polytope.vertices.assign(simplex.v.begin(), simplex.v.end());
  const auto& v = polytope.vertices;
  const Vector3d centroid = 0.25 * (v[0].w + v[1].w + v[2].w + v[3].w);
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (const auto& f : kFace) {
    if (!polytope.add_face(f[0], f[1], f[2])) continue;
    if (polytope.faces.back().normal.dot(v[f[0]].w - centroid) < 0.0) {
      polytope.faces.pop_back();
      polytope.add_face(f[0], f[2], f[1]);
    }
  }
  return polytope;
}

// Expands until the closest face is on D's boundary; returns it (null if none is left).
const Face* expand_to_boundary(const MinkowskiSupport& support, double scale, Polytope* polytope) {
  for (int iteration = 0; iteration < 128; ++iteration) {
    const Face* closest = polytope->closest_face();
    if (closest == nullptr) return nullptr;
    const SupportVertex w = support(closest->normal);
    if (polytope->knows(w) || closest->normal.dot(w.w) - closest->distance <= 1e-13 * scale) return closest;
    polytope->expand(w);
  }
  return polytope->closest_face();
}

// Witness points from the barycentric coordinates of the origin's projection on the face; A's frame.
SignedDistance result_on_face(const Face& face, const std::vector<SupportVertex>& vertices,
                              const Vector3d& ha) {
  const Vector3d& n = face.normal;
  const Vector3d p = face.distance * n;
  const Vector3d& v0 = vertices[face.v[0]].w;
  const Vector3d& v1 = vertices[face.v[1]].w;
  const Vector3d& v2 = vertices[face.v[2]].w;
  const double area = n.dot((v1 - v0).cross(v2 - v0));
  const double l0 = n.dot((v1 - p).cross(v2 - p)) / area;
  const double l1 = n.dot((v2 - p).cross(v0 - p)) / area;
  const std::array<double, 3> lambda{l0, l1, 1.0 - l0 - l1};
  SignedDistance out;
  out.point_a = Vector3d::Zero();
  out.point_b = Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    const SupportVertex& v = vertices[face.v[i]];
    const Vector3d va = vertex_of_a(v.id, ha);
    out.point_a += lambda[i] * va;
    out.point_b += lambda[i] * (va - v.w);
  }
  out.distance = -std::max(face.distance, 0.0);
  out.normal = n;
  return out;
}

SignedDistance to_cell_frame(const Obb& a, SignedDistance d) {
  d.point_a = a.rotation * d.point_a + a.center;
  d.point_b = a.rotation * d.point_b + a.center;
  d.normal = a.rotation * d.normal;
  return d;
}

}  // namespace

SignedDistance epa_penetration(const Obb& a, const Obb& b) {
  const RelativePose rel = relative_pose(a, b);
  Simplex simplex;
  const GjkResult g = gjk(a.half_extents, b.half_extents, rel, &simplex);
  if (!g.intersecting) {
    SignedDistance out;
    out.distance = g.distance;
    out.point_a = g.point_a;
    out.point_b = g.point_b;
    out.normal = (g.point_b - g.point_a).normalized();
    return to_cell_frame(a, out);
  }
  const MinkowskiSupport support{a.half_extents, b.half_extents, rel};
  const double scale = a.half_extents.norm() + b.half_extents.norm() + rel.t.norm();
  const Face* boundary = nullptr;
  Polytope polytope;
  if (grow_to_tetrahedron(support, scale, &simplex)) {
    polytope = initial_polytope(simplex);
    boundary = expand_to_boundary(support, scale, &polytope);
  }
  if (boundary == nullptr) {  // D is flat or degenerated: the separating axes know the depth
    const SeparatingAxis axis = best_separating_axis(a.half_extents, b.half_extents, rel);
    return penetration_witnesses(a, b, rel, std::max(-axis.gap, 0.0), axis.axis);
  }
  return to_cell_frame(a, result_on_face(*boundary, polytope.vertices, a.half_extents));
}

}  // namespace cellmap::collision
