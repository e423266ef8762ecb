// SPDX-License-Identifier: Apache-2.0
#include "cellmap/robot/geometry.hpp"

#include <cmath>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

bool positive(double value) {
  return std::isfinite(value) && value > 0;
}

}  // namespace

Region TriangleMesh::bounds() const {
  if (vertices.empty()) throw Error("triangle mesh has no vertices");
  Region bounds{vertices.front(), vertices.front()};
  for (const Eigen::Vector3d& v : vertices) {
    bounds.min = bounds.min.cwiseMin(v);
    bounds.max = bounds.max.cwiseMax(v);
  }
  return bounds;
}

void TriangleMesh::validate(const std::string& what) const {
  if (triangles.empty()) throw Error(what + ": mesh has no triangles");
  const auto count = static_cast<int>(vertices.size());
  for (const Eigen::Vector3i& t : triangles) {
    if ((t.array() < 0).any() || (t.array() >= count).any()) {
      throw Error(what + ": mesh triangle indexes a vertex out of range");
    }
  }
  for (const Eigen::Vector3d& v : vertices) {
    if (!v.allFinite()) throw Error(what + ": mesh vertex is not finite");
  }
}

LinkBox bounding_box(const LinkShape& shape) {
  LinkBox box{shape.link, shape.X_LG, Eigen::Vector3d::Zero()};
  if (const auto* b = std::get_if<BoxShape>(&shape.geometry)) {
    box.half_extents = b->half_extents;
  } else if (const auto* c = std::get_if<CylinderShape>(&shape.geometry)) {
    box.half_extents = Eigen::Vector3d(c->radius, c->radius, c->half_length);
  } else if (const auto* s = std::get_if<SphereShape>(&shape.geometry)) {
    box.half_extents = Eigen::Vector3d::Constant(s->radius);
  } else {
    const Region bounds = std::get<MeshShape>(shape.geometry).mesh->bounds();
    box.X_LB = shape.X_LG * Eigen::Translation3d(0.5 * (bounds.min + bounds.max));
    box.half_extents = 0.5 * (bounds.max - bounds.min);
  }
  return box;
}

void validate_shape(const LinkShape& shape, const std::string& what) {
  if (!shape.X_LG.matrix().allFinite()) throw Error(what + ": pose is not finite");
  const Eigen::Matrix3d R = shape.X_LG.linear();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0) {
    throw Error(what + ": rotation is not orthonormal");
  }
  bool ok = true;
  if (const auto* b = std::get_if<BoxShape>(&shape.geometry)) {
    ok = positive(b->half_extents.x()) && positive(b->half_extents.y()) && positive(b->half_extents.z());
  } else if (const auto* c = std::get_if<CylinderShape>(&shape.geometry)) {
    ok = positive(c->radius) && positive(c->half_length);
  } else if (const auto* s = std::get_if<SphereShape>(&shape.geometry)) {
    ok = positive(s->radius);
  } else {
    const MeshShape& mesh = std::get<MeshShape>(shape.geometry);
    if (!mesh.mesh) throw Error(what + ": mesh is missing");
    mesh.mesh->validate(what);
  }
  if (!ok) throw Error(what + ": sizes must be positive and finite");
}

std::size_t triangle_count(const LinkGeometry& geometry) {
  const auto* mesh = std::get_if<MeshShape>(&geometry);
  return mesh && mesh->mesh ? mesh->mesh->triangles.size() : 0;
}

}  // namespace cellmap
