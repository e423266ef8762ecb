// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: a CPU z-buffer for one pinhole camera, into which the padded robot's triangles are drawn.
//
// Written here because no Debian library rasterizes triangles into a depth buffer on the CPU for this: the
// GPU paths (OpenGL/EGL, as MoveIt's filter uses) need a display or GPU driver the daemon cannot count on,
// VTK/PCL's renderers go through OpenGL too, and OSMesa would pull in a whole software GL stack for a few
// thousand triangles. The loop is small: clip at a near plane, project, fill pixel centres by edge
// functions, keep the nearest depth.

#include <Eigen/Core>

#include <vector>

#include "cellmap/frame/frame.hpp"

namespace cellmap::self_filter {

/// Nearest depth (along the optical axis z, metres) of the triangles drawn so far at every pixel centre of
/// `intrinsics`' image. Pixel (u, v) samples the ray through ((u − cx)/fx, (v − cy)/fy, 1), the ray
/// depth_to_points back-projects it along. Stored as 1/z (0 = nothing drawn), since 1/z is affine in the
/// image plane.
class DepthBuffer {
 public:
  explicit DepthBuffer(const PinholeIntrinsics& intrinsics);

  /// Draws triangles given by their vertices in the sensor frame S (either winding). Parts nearer than the
  /// near plane (1 mm) are clipped off.
  void draw(const std::vector<Eigen::Vector3f>& vertices_S, const std::vector<Eigen::Vector3i>& triangles);

  /// 1/z of the nearest surface at pixel (u, v), 0 where nothing was drawn; (u, v) must be inside the image.
  [[nodiscard]] float inverse_depth(int u, int v) const {
    return inverse_depth_[std::size_t(v) * width_ + u];
  }
  [[nodiscard]] bool empty() const { return drawn_ == 0; }
  /// Pixels covered by at least one triangle.
  [[nodiscard]] std::size_t covered() const;

 private:
  void fill(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c);

  int width_, height_;
  float fx_, fy_, cx_, cy_;
  std::vector<float> inverse_depth_;
  std::size_t drawn_ = 0;
};

}  // namespace cellmap::self_filter
