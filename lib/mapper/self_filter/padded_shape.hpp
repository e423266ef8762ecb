// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: the robot's collision shapes grown by the padding and turned into triangles in their own frame G.

#include <Eigen/Geometry>

#include <vector>

#include "cellmap/robot/geometry.hpp"
#include "cellmap/self_filter/self_filter.hpp"

namespace cellmap::self_filter {

/// One padded shape as triangles in its frame G, and the padded solid's extent for the "sensor inside" test.
struct PaddedShape {
  enum class Kind { kBox, kCylinder, kSphere, kMesh };
  Kind kind = Kind::kBox;
  /// kBox and kMesh: half extents of the padded box (a mesh: of its padded vertices' bounds, about
  /// `centre_G`); kCylinder: (radius, radius, half length); kSphere: the radius thrice.
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  Eigen::Vector3d centre_G = Eigen::Vector3d::Zero();
  /// Tessellated primitives circumscribe the padded solid, so the triangles never cut into it.
  std::vector<Eigen::Vector3f> vertices_G;
  std::vector<Eigen::Vector3i> triangles;
  double bounding_radius = 0.0;  ///< every vertex lies within this distance of centre_G

  /// True if p_G lies inside the padded solid (meshes: inside their padded bounds).
  [[nodiscard]] bool contains(const Eigen::Vector3d& p_G) const;
};

/// `geometry` grown by `config`'s padding (scale about the centre, then the offset in metres).
[[nodiscard]] PaddedShape pad(const LinkGeometry& geometry, const SelfFilterConfig& config);

}  // namespace cellmap::self_filter
