#include "cellmap/sweep/sweep.hpp"

#include <cmath>

namespace cellmap {

Cloud Sweep::merged() const {
  Cloud all;
  all.reserve(point_count());
  for (const Scan& scan : scans) all += scan.points_C;
  return all;
}

std::size_t Sweep::point_count() const {
  std::size_t n = 0;
  for (const Scan& scan : scans) n += scan.points_C.size();
  return n;
}

Scan to_scan(const Frame& frame) {
  Scan scan;
  scan.origin_C = frame.X_CS.translation();
  const Eigen::Isometry3f X_CS = frame.X_CS.cast<float>();
  auto& points_C = scan.points_C.points;  // filled directly: the cloud's push_back also rewrites its size
  points_C.reserve(frame.points_S.size());
  for (const pcl::PointXYZ& p : frame.points_S) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const Eigen::Vector3f p_C = X_CS * p.getVector3fMap();
    points_C.emplace_back(p_C.x(), p_C.y(), p_C.z());
  }
  scan.points_C.width = static_cast<std::uint32_t>(scan.points_C.size());
  scan.points_C.height = 1;
  scan.points_C.is_dense = true;
  return scan;
}

Sweep merge_frames(const std::vector<Frame>& frames) {
  Sweep sweep;
  sweep.scans.reserve(frames.size());
  for (const Frame& frame : frames) sweep.scans.push_back(to_scan(frame));
  if (!frames.empty()) sweep.stamp = frames.back().stamp;
  return sweep;
}

}  // namespace cellmap
