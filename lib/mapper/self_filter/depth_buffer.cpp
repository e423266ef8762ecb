// SPDX-License-Identifier: Apache-2.0
#include "depth_buffer.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace cellmap::self_filter {
namespace {

constexpr float kNear = 0.001f;  // metres

// A vertex projected to the image: pixel coordinates and 1/z.
struct Projected {
  float u, v, inverse_z;
};

float edge(const Projected& a, const Projected& b, float u, float v) {
  return (b.u - a.u) * (v - a.v) - (b.v - a.v) * (u - a.u);
}

}  // namespace

DepthBuffer::DepthBuffer(const PinholeIntrinsics& intrinsics)
    : width_(intrinsics.width),
      height_(intrinsics.height),
      fx_(float(intrinsics.fx)),
      fy_(float(intrinsics.fy)),
      cx_(float(intrinsics.cx)),
      cy_(float(intrinsics.cy)),
      inverse_depth_(std::size_t(intrinsics.width) * std::size_t(intrinsics.height), 0.0f) {}

void DepthBuffer::draw(const std::vector<Eigen::Vector3f>& vertices_S,
                       const std::vector<Eigen::Vector3i>& triangles) {
  for (const Eigen::Vector3i& t : triangles) {
    const Eigen::Vector3f* v[3] = {&vertices_S[std::size_t(t[0])], &vertices_S[std::size_t(t[1])],
                                   &vertices_S[std::size_t(t[2])]};
    // Clip against z = near: keep the polygon's part in front (at most 4 vertices), then fan it.
    std::array<Eigen::Vector3f, 4> polygon;
    int count = 0;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& p = *v[k];
      const Eigen::Vector3f& q = *v[(k + 1) % 3];
      const bool p_in = p.z() >= kNear, q_in = q.z() >= kNear;
      if (p_in) polygon[std::size_t(count++)] = p;
      if (p_in != q_in) polygon[std::size_t(count++)] = p + (q - p) * ((kNear - p.z()) / (q.z() - p.z()));
    }
    for (int k = 2; k < count; ++k) fill(polygon[0], polygon[std::size_t(k - 1)], polygon[std::size_t(k)]);
  }
}

void DepthBuffer::fill(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
  auto project = [this](const Eigen::Vector3f& p) {
    const float inverse_z = 1.0f / p.z();
    return Projected{fx_ * p.x() * inverse_z + cx_, fy_ * p.y() * inverse_z + cy_, inverse_z};
  };
  const Projected p0 = project(a), p1 = project(b), p2 = project(c);
  const float area = edge(p0, p1, p2.u, p2.v);
  if (!(std::abs(area) > 1e-12f)) return;  // degenerate (or NaN)
  // Pixel centres are at integer coordinates; take every centre on or inside the triangle.
  const int u0 = std::max(0, int(std::ceil(std::min({p0.u, p1.u, p2.u}))));
  const int u1 = std::min(width_ - 1, int(std::floor(std::max({p0.u, p1.u, p2.u}))));
  const int v0 = std::max(0, int(std::ceil(std::min({p0.v, p1.v, p2.v}))));
  const int v1 = std::min(height_ - 1, int(std::floor(std::max({p0.v, p1.v, p2.v}))));
  if (u0 > u1 || v0 > v1) return;
  ++drawn_;
  // Barycentric weights are affine in (u, v): step them along the row instead of re-evaluating.
  const float inverse_area = 1.0f / area;
  const float du[3] = {-(p2.v - p1.v) * inverse_area, -(p0.v - p2.v) * inverse_area,
                       -(p1.v - p0.v) * inverse_area};
  for (int v = v0; v <= v1; ++v) {
    float w0 = edge(p1, p2, float(u0), float(v)) * inverse_area;
    float w1 = edge(p2, p0, float(u0), float(v)) * inverse_area;
    float w2 = edge(p0, p1, float(u0), float(v)) * inverse_area;
    float* row = inverse_depth_.data() + std::size_t(v) * std::size_t(width_);
    for (int u = u0; u <= u1; ++u, w0 += du[0], w1 += du[1], w2 += du[2]) {
      // A small tolerance keeps pixel centres on shared edges inside both triangles (no cracks).
      if (w0 < -1e-5f || w1 < -1e-5f || w2 < -1e-5f) continue;
      const float inverse_z = w0 * p0.inverse_z + w1 * p1.inverse_z + w2 * p2.inverse_z;
      row[u] = std::max(row[u], inverse_z);
    }
  }
}

std::size_t DepthBuffer::covered() const {
  return std::size_t(
      std::count_if(inverse_depth_.begin(), inverse_depth_.end(), [](float d) { return d > 0; }));
}

}  // namespace cellmap::self_filter
