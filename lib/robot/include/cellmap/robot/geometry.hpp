// SPDX-License-Identifier: Apache-2.0
#pragma once
// Solid shapes and triangle meshes: the collision geometry of a robot's links and the obstacles of the
// simulated cell. Plain value types in the shape's own frame G; Eigen only (meshes are read from files by the
// urdf stage).

#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "cellmap/common/region.hpp"

namespace cellmap {

/// A box centred on its frame G, with half extents along G's x, y and z axes (metres, > 0).
struct BoxShape final {
  Eigen::Vector3d half_extents = Eigen::Vector3d::Ones();
};
/// A solid cylinder centred on its frame G, its axis along G's z (metres, > 0).
struct CylinderShape final {
  double radius = 1.0;
  double half_length = 1.0;
};
/// A solid sphere centred on its frame G (metres, > 0).
struct SphereShape final {
  double radius = 1.0;
};

/// A triangle mesh in its frame G (metres). Triangles index `vertices`; their winding is not relied on (a
/// ray hits either side), so open or inconsistently wound meshes of real robot descriptions work as they are.
struct TriangleMesh final {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;

  /// The axis-aligned bounds of the vertices in G. @throws Error if the mesh has no vertices.
  [[nodiscard]] Region bounds() const;
  /// @throws Error (prefixed with `what`) if there is no triangle, an index is out of range or a vertex is
  /// not finite.
  void validate(const std::string& what) const;
};

/// A mesh as a solid's surface. Shared and immutable: copies of a robot share its meshes.
struct MeshShape final {
  std::shared_ptr<const TriangleMesh> mesh;
};

/// Collision geometry of a robot link.
using LinkGeometry = std::variant<BoxShape, CylinderShape, SphereShape, MeshShape>;

/// One collision shape fixed to link L: the shape's frame G in the link frame is X_LG.
struct LinkShape final {
  std::string link;
  Eigen::Isometry3d X_LG = Eigen::Isometry3d::Identity();
  LinkGeometry geometry = BoxShape{};
};

/// A box fixed to link L of a robot (collision geometry): pose X_LB of the box in the link frame, half
/// extents in metres.
struct LinkBox final {
  std::string link;
  Eigen::Isometry3d X_LB = Eigen::Isometry3d::Identity();
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
};

/// The tightest box about `shape` aligned with its frame G, as a box on its link: a box is itself, a
/// cylinder (r, r, half length), a sphere a cube of half extent r, a mesh the bounds of its vertices in G.
/// Every point of the shape lies inside. @throws Error as TriangleMesh::bounds.
[[nodiscard]] LinkBox bounding_box(const LinkShape& shape);

/// Checks sizes (> 0 and finite), the pose (finite, rotation orthonormal) and meshes
/// (TriangleMesh::validate).
/// @throws Error starting with `what`.
void validate_shape(const LinkShape& shape, const std::string& what);

/// Number of triangles of a shape (0 for the primitives).
[[nodiscard]] std::size_t triangle_count(const LinkGeometry& geometry);

}  // namespace cellmap
