// SPDX-License-Identifier: Apache-2.0
#pragma once
// A bounding-volume hierarchy over a triangle mesh for ray casting (internal to the sim stage).
//
// Written by hand: of the libraries at hand FCL answers distance and collision queries, not first hits along
// rays, and PCL's ray casting goes through VTK, which cellmap builds without; a median-split AABB tree with
// Möller–Trumbore triangle tests is a page of code.

#include <Eigen/Core>

#include <optional>
#include <vector>

#include "cellmap/robot/geometry.hpp"

namespace cellmap::sim {

/// Immutable after construction; any number of threads may intersect concurrently.
class MeshBvh final {
 public:
  /// @throws Error as TriangleMesh::validate.
  explicit MeshBvh(const TriangleMesh& mesh);

  /// Distance t in [0, t_max] along the ray o + t·d (mesh frame; d need not be unit, t is in units of |d|) to
  /// the nearest triangle, either side; nullopt if none is that near.
  [[nodiscard]] std::optional<double> intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                                double t_max) const;

  /// Bounds of the mesh's vertices.
  [[nodiscard]] const Region& bounds() const { return bounds_; }
  [[nodiscard]] std::size_t triangles() const { return triangles_.size(); }

 private:
  struct Triangle {
    Eigen::Vector3d v0, e1, e2;  // a corner and the two edges from it
  };
  struct Node {
    Eigen::Vector3d min, max;
    int first = 0;  // leaf: first triangle; inner: index of the right child (the left one is the next node)
    int count = 0;  // triangles in a leaf; 0 for an inner node
  };
  int build(std::vector<int>& order, int begin, int end, const std::vector<Eigen::Vector3d>& centroids);

  std::vector<Triangle> triangles_;
  std::vector<Node> nodes_;
  Region bounds_;
};

}  // namespace cellmap::sim
