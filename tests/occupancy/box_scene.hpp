// SPDX-License-Identifier: Apache-2.0
#pragma once
// Test and benchmark support: renders deterministic depth frames of a scene of axis-aligned boxes with a
// pinhole camera (optionally with Gaussian depth noise), until the simulator stage can stand in.

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "cellmap/frame/frame.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap::testing {

struct AlignedBox {
  Eigen::Vector3d min_C;
  Eigen::Vector3d max_C;
};

/// Distance along the unit ray (o, d) to the nearest box surface, or +inf (slab test).
inline double ray_distance(const std::vector<AlignedBox>& boxes, const Eigen::Vector3d& o,
                           const Eigen::Vector3d& d) {
  double best = std::numeric_limits<double>::infinity();
  for (const AlignedBox& box : boxes) {
    double t_near = 0.0;
    double t_far = std::numeric_limits<double>::infinity();
    bool hit = true;
    for (int i = 0; i < 3 && hit; ++i) {
      if (std::fabs(d[i]) < 1e-12) {
        hit = o[i] >= box.min_C[i] && o[i] <= box.max_C[i];
        continue;
      }
      double t0 = (box.min_C[i] - o[i]) / d[i];
      double t1 = (box.max_C[i] - o[i]) / d[i];
      if (t0 > t1) std::swap(t0, t1);
      t_near = std::max(t_near, t0);
      t_far = std::min(t_far, t1);
      hit = t_near <= t_far;
    }
    if (hit && t_near > 0.0) best = std::min(best, t_near);
  }
  return best;
}

/// A depth frame of `boxes` seen by a camera at X_CS (sensor frame: x right, y down, z forward), as a scan in
/// the cell frame. Depths get N(0, noise_sigma) metres of noise when `rng` is given, then millimetre
/// quantization.
inline Scan render_scan(const std::vector<AlignedBox>& boxes, const Eigen::Isometry3d& X_CS,
                        const PinholeIntrinsics& intrinsics, double noise_sigma = 0.0,
                        std::mt19937* rng = nullptr) {
  DepthImage image;
  image.intrinsics = intrinsics;
  image.depth.assign(static_cast<std::size_t>(intrinsics.width) * intrinsics.height, 0);
  std::normal_distribution<double> noise(0.0, noise_sigma > 0.0 ? noise_sigma : 1.0);
  const Eigen::Vector3d o_C = X_CS.translation();
  for (int v = 0; v < intrinsics.height; ++v) {
    for (int u = 0; u < intrinsics.width; ++u) {
      const Eigen::Vector3d ray_S((u - intrinsics.cx) / intrinsics.fx, (v - intrinsics.cy) / intrinsics.fy,
                                  1.0);
      const Eigen::Vector3d d_C = (X_CS.linear() * ray_S).normalized();
      const double t = ray_distance(boxes, o_C, d_C);
      if (!std::isfinite(t)) continue;
      double z = t / ray_S.norm();  // depth along the optical axis
      if (rng != nullptr && noise_sigma > 0.0) z += noise(*rng);
      const double raw = std::round(z / intrinsics.depth_scale);
      if (raw > 0 && raw < 65535)
        image.depth[static_cast<std::size_t>(v) * intrinsics.width + u] = std::uint16_t(raw);
    }
  }
  Scan scan;
  scan.origin_C = o_C;
  const Cloud points_S = depth_to_points(image);
  scan.points_C.reserve(points_S.size());
  for (const auto& p : points_S.points) {
    const Eigen::Vector3d p_C = X_CS * Eigen::Vector3d(p.x, p.y, p.z);
    scan.points_C.push_back(pcl::PointXYZ(float(p_C.x()), float(p_C.y()), float(p_C.z())));
  }
  return scan;
}

/// Kinect-class intrinsics scaled to `width` × `height` (525 px focal length at 640 × 480).
inline PinholeIntrinsics kinect_intrinsics(int width = 640, int height = 480) {
  PinholeIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 525.0 * width / 640.0;
  k.cx = width / 2.0;
  k.cy = height / 2.0;
  k.max_range = 10.0;
  return k;
}

/// A small room in camera-style coordinates (y down): floor at y = 1 m, back wall at z = 3.5 m, side walls at
/// x = ±1.8 m, and two boxes on the floor. The camera at the identity pose looks into it.
inline std::vector<AlignedBox> box_room() {
  return {
      {{-2.0, 1.0, 0.0}, {2.0, 1.1, 3.6}},    // floor
      {{-2.0, -1.5, 3.5}, {2.0, 1.1, 3.6}},   // back wall
      {{-1.9, -1.5, 0.0}, {-1.8, 1.1, 3.6}},  // left wall
      {{1.8, -1.5, 0.0}, {1.9, 1.1, 3.6}},    // right wall
      {{-0.6, 0.5, 1.8}, {-0.1, 1.0, 2.3}},   // box A on the floor
      {{0.3, 0.7, 2.4}, {0.7, 1.0, 2.8}},     // box B on the floor
  };
}

}  // namespace cellmap::testing
