// SPDX-License-Identifier: Apache-2.0
#pragma once
// Synthetic scenes for the segmentation tests: grid-sampled surfaces as a depth sensor at `viewpoint` sees
// them (only faces turned toward it), with the true object of every point.

#include <Eigen/Geometry>

#include <vector>

#include "cellmap/frame/cloud.hpp"
#include "cellmap/segment/box_split.hpp"

namespace cellmap::test {

struct Scene {
  Cloud points;
  std::vector<int> object;  ///< per point: 0 = floor plane, 1.. = boxes in the order added
  int objects = 0;          ///< number of boxes

  explicit Scene(const Eigen::Vector3f& viewpoint) {
    points.sensor_origin_ = Eigen::Vector4f(viewpoint.x(), viewpoint.y(), viewpoint.z(), 0.0f);
  }

  Eigen::Vector3f viewpoint() const { return points.sensor_origin_.head<3>(); }

  /// The visible faces of a box (centre p_CB, half extents, rotation R_CB), sampled every `step` metres.
  void add_box(const Eigen::Vector3d& p_CB, const Eigen::Vector3d& half, const Eigen::Matrix3d& R_CB,
               double step = 0.005) {
    ++objects;
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (double sign : {-1.0, 1.0}) {
        if (half[u] <= 0.0 || half[v] <= 0.0) continue;  // a face of zero area
        const Eigen::Vector3d n_C = sign * R_CB.col(axis);
        const Eigen::Vector3d face_C = p_CB + sign * half[axis] * R_CB.col(axis);
        if (n_C.dot(viewpoint().cast<double>() - face_C) <= 0.0) continue;
        const int nu = static_cast<int>(std::round(2 * half[u] / step));
        const int nv = static_cast<int>(std::round(2 * half[v] / step));
        for (int a = 0; a <= nu; ++a) {
          for (int b = 0; b <= nv; ++b) {
            Eigen::Vector3d p_B;
            p_B[axis] = sign * half[axis];
            p_B[u] = -half[u] + 2 * half[u] * a / nu;
            p_B[v] = -half[v] + 2 * half[v] * b / nv;
            add((p_CB + R_CB * p_B).cast<float>(), objects);
          }
        }
      }
    }
  }

  /// The floor z = 0 over [-extent, extent]², without the points under `footprints` (hidden by the boxes).
  void add_floor(double extent, const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& footprints,
                 double step = 0.005) {
    const int n = static_cast<int>(std::round(2 * extent / step));
    for (int a = 0; a <= n; ++a) {
      for (int b = 0; b <= n; ++b) {
        const Eigen::Vector2d p(-extent + step * a, -extent + step * b);
        bool hidden = false;
        for (const auto& [low, high] : footprints) {
          hidden |= (p.array() > low.array() - 1e-9).all() && (p.array() < high.array() + 1e-9).all();
        }
        if (!hidden) add(Eigen::Vector3f(p.x(), p.y(), 0.0f), 0);
      }
    }
  }

  void add(const Eigen::Vector3f& p, int id) {
    points.push_back({p.x(), p.y(), p.z()});
    object.push_back(id);
  }
};

/// Split and join parameters for these scenes (sampled every 5 mm, seen from about a metre and a half).
inline BoxSplitParams split_params() {
  BoxSplitParams p;
  p.angular_step = 0.005;
  p.margin = 0.01;
  p.adjacency = 0.02;
  p.gap = 0.012;
  return p;
}

}  // namespace cellmap::test
