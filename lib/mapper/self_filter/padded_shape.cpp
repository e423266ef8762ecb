// SPDX-License-Identifier: Apache-2.0
#include "padded_shape.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

namespace cellmap::self_filter {
namespace {

// Segments of a tessellated circle; with the circumscribing factor the polygon contains the circle.
constexpr int kSegments = 24;
constexpr int kRings = 12;  // latitude bands of a sphere

double grown(double size, const SelfFilterConfig& config) {
  return size * config.padding_scale + config.padding;
}

void finish(PaddedShape& shape) {
  for (const Eigen::Vector3f& v : shape.vertices_G) {
    shape.bounding_radius = std::max(shape.bounding_radius, (v.cast<double>() - shape.centre_G).norm());
  }
}

PaddedShape box(const Eigen::Vector3d& half) {
  PaddedShape shape;
  shape.kind = PaddedShape::Kind::kBox;
  shape.half = half;
  for (int i = 0; i < 8; ++i) {
    shape.vertices_G.emplace_back(
        Eigen::Vector3d((i & 1 ? 1 : -1) * half.x(), (i & 2 ? 1 : -1) * half.y(), (i & 4 ? 1 : -1) * half.z())
            .cast<float>());
  }
  // Two triangles per face; faces at -x, +x, -y, +y, -z, +z (corner bit 1 = x, 2 = y, 4 = z).
  const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& f : faces) {
    shape.triangles.emplace_back(f[0], f[1], f[2]);
    shape.triangles.emplace_back(f[0], f[2], f[3]);
  }
  finish(shape);
  return shape;
}

PaddedShape cylinder(double radius, double half_length) {
  PaddedShape shape;
  shape.kind = PaddedShape::Kind::kCylinder;
  shape.half = Eigen::Vector3d(radius, radius, half_length);
  const double r = radius / std::cos(M_PI / kSegments);  // polygon's edges touch the circle from outside
  for (const double z : {-half_length, half_length}) {
    for (int i = 0; i < kSegments; ++i) {
      const double a = 2.0 * M_PI * i / kSegments;
      shape.vertices_G.emplace_back(Eigen::Vector3d(r * std::cos(a), r * std::sin(a), z).cast<float>());
    }
  }
  const int bottom = static_cast<int>(shape.vertices_G.size());
  shape.vertices_G.emplace_back(0.0f, 0.0f, static_cast<float>(-half_length));
  shape.vertices_G.emplace_back(0.0f, 0.0f, static_cast<float>(half_length));
  for (int i = 0; i < kSegments; ++i) {
    const int j = (i + 1) % kSegments;
    shape.triangles.emplace_back(i, j, kSegments + j);
    shape.triangles.emplace_back(i, kSegments + j, kSegments + i);
    shape.triangles.emplace_back(bottom, j, i);
    shape.triangles.emplace_back(bottom + 1, kSegments + i, kSegments + j);
  }
  finish(shape);
  return shape;
}

PaddedShape sphere(double radius) {
  PaddedShape shape;
  shape.kind = PaddedShape::Kind::kSphere;
  shape.half = Eigen::Vector3d::Constant(radius);
  // A latitude-longitude polyhedron whose faces stay outside the sphere: every face is within one band and
  // one segment, so its distance from the centre is at least r·cos(half the segment)·cos(half the band);
  // using full angles leaves a margin for the non-planar quads split into triangles.
  const double r = radius / (std::cos(M_PI / kSegments) * std::cos(M_PI / kRings));
  for (int ring = 0; ring <= kRings; ++ring) {
    const double polar = M_PI * ring / kRings;
    for (int i = 0; i < kSegments; ++i) {
      const double a = 2.0 * M_PI * i / kSegments;
      shape.vertices_G.emplace_back(Eigen::Vector3d(r * std::sin(polar) * std::cos(a),
                                                    r * std::sin(polar) * std::sin(a), r * std::cos(polar))
                                        .cast<float>());
    }
  }
  for (int ring = 0; ring < kRings; ++ring) {
    for (int i = 0; i < kSegments; ++i) {
      const int j = (i + 1) % kSegments;
      const int a = ring * kSegments + i, b = ring * kSegments + j;
      const int c = (ring + 1) * kSegments + j, d = (ring + 1) * kSegments + i;
      shape.triangles.emplace_back(a, b, c);
      shape.triangles.emplace_back(a, c, d);
    }
  }
  finish(shape);
  return shape;
}

// Vertices at the same position become one, so that moving them along their normals keeps the surface
// closed (STL files repeat every vertex per triangle).
TriangleMesh welded(const TriangleMesh& mesh) {
  TriangleMesh out;
  std::map<std::array<double, 3>, int> index;
  std::vector<int> remap(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d& v = mesh.vertices[i];
    const auto [it, added] =
        index.emplace(std::array<double, 3>{v.x(), v.y(), v.z()}, int(out.vertices.size()));
    if (added) out.vertices.push_back(v);
    remap[i] = it->second;
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3i w(remap[std::size_t(t[0])], remap[std::size_t(t[1])], remap[std::size_t(t[2])]);
    if (w[0] != w[1] && w[1] != w[2] && w[0] != w[2]) out.triangles.push_back(w);
  }
  return out;
}

// True if every edge is used at most once in each direction: the winding is consistent, so the normals'
// orientation can come from it.
bool consistently_wound(const TriangleMesh& mesh) {
  std::set<std::pair<int, int>> edges;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (!edges.emplace(t[k], t[(k + 1) % 3]).second) return false;
    }
  }
  return true;
}

// Outward unit face normals (zero for degenerate faces). A consistently wound mesh is oriented by its signed
// volume; otherwise each face is turned away from the centre of the bounds (right for convex-ish links).
std::vector<Eigen::Vector3d> face_normals(const TriangleMesh& mesh, const Eigen::Vector3d& centre) {
  std::vector<Eigen::Vector3d> normals;
  double signed_volume = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[std::size_t(t[0])];
    const Eigen::Vector3d& b = mesh.vertices[std::size_t(t[1])];
    const Eigen::Vector3d& c = mesh.vertices[std::size_t(t[2])];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    signed_volume += (a - centre).dot((b - centre).cross(c - centre));
    normals.push_back(n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero());
  }
  if (consistently_wound(mesh)) {
    if (signed_volume < 0) {
      for (Eigen::Vector3d& n : normals) n = -n;
    }
    return normals;
  }
  for (std::size_t f = 0; f < normals.size(); ++f) {
    const Eigen::Vector3i& t = mesh.triangles[f];
    const Eigen::Vector3d middle = (mesh.vertices[std::size_t(t[0])] + mesh.vertices[std::size_t(t[1])] +
                                    mesh.vertices[std::size_t(t[2])]) /
                                   3.0;
    if (normals[f].dot(middle - centre) < 0) normals[f] = -normals[f];
  }
  return normals;
}

PaddedShape mesh(const TriangleMesh& original, const SelfFilterConfig& config) {
  const TriangleMesh m = welded(original);
  const Region bounds = m.bounds();
  const Eigen::Vector3d centre = 0.5 * (bounds.min + bounds.max);
  const std::vector<Eigen::Vector3d> normals = face_normals(m, centre);
  // Vertex normal: area-agnostic mean of its faces' normals; the vertex moves along it far enough that each
  // of its faces moves out by the padding (1 / the smallest cosine to a face normal, at most 3×: sharp cones
  // would otherwise shoot out).
  std::vector<Eigen::Vector3d> vertex_normal(m.vertices.size(), Eigen::Vector3d::Zero());
  for (std::size_t f = 0; f < m.triangles.size(); ++f) {
    for (int k = 0; k < 3; ++k) vertex_normal[std::size_t(m.triangles[f][k])] += normals[f];
  }
  std::vector<double> stretch(m.vertices.size(), 1.0);
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    Eigen::Vector3d& n = vertex_normal[v];
    n = n.norm() > 1e-12 ? Eigen::Vector3d(n.normalized()) : (m.vertices[v] - centre).normalized();
    if (!n.allFinite()) n = Eigen::Vector3d::UnitZ();
  }
  for (std::size_t f = 0; f < m.triangles.size(); ++f) {
    if (normals[f].isZero()) continue;
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = std::size_t(m.triangles[f][k]);
      const double cosine = std::max(vertex_normal[v].dot(normals[f]), 1.0 / 3.0);
      stretch[v] = std::max(stretch[v], 1.0 / cosine);
    }
  }
  PaddedShape shape;
  shape.kind = PaddedShape::Kind::kMesh;
  Region padded{Eigen::Vector3d::Constant(INFINITY), Eigen::Vector3d::Constant(-INFINITY)};
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    const Eigen::Vector3d p = centre + (m.vertices[v] - centre) * config.padding_scale +
                              vertex_normal[v] * (config.padding * stretch[v]);
    shape.vertices_G.push_back(p.cast<float>());
    padded.min = padded.min.cwiseMin(p);
    padded.max = padded.max.cwiseMax(p);
  }
  shape.triangles = m.triangles;
  shape.centre_G = 0.5 * (padded.min + padded.max);
  shape.half = 0.5 * (padded.max - padded.min);
  finish(shape);
  return shape;
}

}  // namespace

bool PaddedShape::contains(const Eigen::Vector3d& p_G) const {
  const Eigen::Vector3d d = p_G - centre_G;
  switch (kind) {
    case Kind::kCylinder:
      return d.head<2>().norm() <= half.x() && std::abs(d.z()) <= half.z();
    case Kind::kSphere:
      return d.norm() <= half.x();
    case Kind::kBox:
    case Kind::kMesh:
      break;
  }
  return (d.cwiseAbs().array() <= half.array()).all();
}

PaddedShape pad(const LinkGeometry& geometry, const SelfFilterConfig& config) {
  if (const auto* b = std::get_if<BoxShape>(&geometry)) {
    return box(b->half_extents.unaryExpr([&](double h) { return grown(h, config); }));
  }
  if (const auto* c = std::get_if<CylinderShape>(&geometry)) {
    return cylinder(grown(c->radius, config), grown(c->half_length, config));
  }
  if (const auto* s = std::get_if<SphereShape>(&geometry)) return sphere(grown(s->radius, config));
  return mesh(*std::get<MeshShape>(geometry).mesh, config);
}

}  // namespace cellmap::self_filter
