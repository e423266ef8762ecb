// SPDX-License-Identifier: Apache-2.0
#include "no_return.hpp"

#include <Eigen/Geometry>

#include <algorithm>

namespace cellmap {

namespace {

// A line scanner's beams without a return, each cleared up to `range` or its own end, whichever is nearer.
std::size_t add_beams(const Frame& frame, float range, Scan& scan) {
  const Eigen::Isometry3f X_CS = frame.X_CS.cast<float>();
  std::size_t added = 0;
  for (const pcl::PointXYZ& end : frame.no_return_S) {
    const Eigen::Vector3f end_S = end.getVector3fMap();
    const float length = end_S.norm();
    if (!(length > 0.0f)) continue;
    const Eigen::Vector3f end_C = X_CS * (end_S * (std::min(length, range) / length));
    scan.clear_C.push_back(pcl::PointXYZ(end_C.x(), end_C.y(), end_C.z()));
    ++added;
  }
  return added;
}

}  // namespace

std::size_t add_no_return_rays(const Frame& frame, double range, unsigned phase, Scan& scan) {
  if (!(range > 0.0)) return 0;
  if (!frame.no_return_S.empty()) {
    const std::size_t added = add_beams(frame, float(range), scan);
    set_unorganized(scan.clear_C);
    return added;
  }
  if (!frame.depth) return 0;
  const DepthImage& image = *frame.depth;
  const PinholeIntrinsics& in = image.intrinsics;
  const auto width = static_cast<std::size_t>(in.width), height = static_cast<std::size_t>(in.height);
  if (image.depth.size() != width * height) return 0;
  const Eigen::Isometry3f X_CS = frame.X_CS.cast<float>();
  const std::size_t before = scan.clear_C.size();
  for (std::size_t v = (phase / 2) % 2; v < height; v += 2) {
    for (std::size_t u = phase % 2; u < width; u += 2) {
      if (image.depth[v * width + u] != 0) continue;
      const Eigen::Vector3f sight_S(float((double(u) - in.cx) / in.fx), float((double(v) - in.cy) / in.fy),
                                    1.0f);
      const Eigen::Vector3f end_C = X_CS * (sight_S.normalized() * float(range));
      scan.clear_C.push_back(pcl::PointXYZ(end_C.x(), end_C.y(), end_C.z()));
    }
  }
  set_unorganized(scan.clear_C);
  return scan.clear_C.size() - before;
}

}  // namespace cellmap
