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

namespace {

bool finite(const pcl::PointXYZ& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

pcl::PointXYZ to_cell(const Eigen::Isometry3f& X_CS, const pcl::PointXYZ& p_S) {
  const Eigen::Vector3f p_C = X_CS * p_S.getVector3fMap();
  return {p_C.x(), p_C.y(), p_C.z()};
}

void set_unorganized(Cloud& cloud) {
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
}

}  // namespace

Scan to_scan(const Frame& frame) {
  Scan scan;
  scan.origin_C = frame.X_CS.translation();
  const Eigen::Isometry3f X_CS = frame.X_CS.cast<float>();
  auto& points_C = scan.points_C.points;  // filled directly: the cloud's push_back also rewrites its size
  points_C.reserve(frame.points_S.size());
  for (const pcl::PointXYZ& p : frame.points_S) {
    if (finite(p)) points_C.push_back(to_cell(X_CS, p));
  }
  set_unorganized(scan.points_C);
  return scan;
}

Scan move_to_scan(Frame& frame) {
  Scan scan;
  scan.origin_C = frame.X_CS.translation();
  const Eigen::Isometry3f X_CS = frame.X_CS.cast<float>();
  auto& points = frame.points_S.points;
  std::size_t kept = 0;
  for (const pcl::PointXYZ& p : points) {
    if (finite(p)) points[kept++] = to_cell(X_CS, p);
  }
  points.resize(kept);
  scan.points_C.points.swap(points);
  set_unorganized(scan.points_C);
  frame.points_S.clear();
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
