// SPDX-License-Identifier: Apache-2.0
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

// Writes the coordinates one by one: a PointXYZ built and returned whole is stored in parts (x, y, z, then
// the padding) and read back as one 16-byte word, which stalls store forwarding on every point (it made
// the conversion of a native D435 frame 3.6 ms instead of under 1).
void to_cell(const Eigen::Matrix3f& R_CS, const Eigen::Vector3f& t_CS, const pcl::PointXYZ& p_S,
             pcl::PointXYZ& p_C) {
  const float x = p_S.x, y = p_S.y, z = p_S.z;
  p_C.x = R_CS(0, 0) * x + R_CS(0, 1) * y + R_CS(0, 2) * z + t_CS.x();
  p_C.y = R_CS(1, 0) * x + R_CS(1, 1) * y + R_CS(1, 2) * z + t_CS.y();
  p_C.z = R_CS(2, 0) * x + R_CS(2, 1) * y + R_CS(2, 2) * z + t_CS.z();
}

}  // namespace

Scan to_scan(const Frame& frame) {
  Scan scan;
  scan.origin_C = frame.X_CS.translation();
  const Eigen::Matrix3f R_CS = frame.X_CS.linear().cast<float>();
  const Eigen::Vector3f t_CS = frame.X_CS.translation().cast<float>();
  auto& points_C = scan.points_C.points;  // filled directly: the cloud's push_back also rewrites its size
  points_C.resize(frame.points_S.size());
  std::size_t kept = 0;
  for (const pcl::PointXYZ& p : frame.points_S) {
    if (finite(p)) to_cell(R_CS, t_CS, p, points_C[kept++]);
  }
  points_C.resize(kept);
  set_unorganized(scan.points_C);
  return scan;
}

Scan move_to_scan(Frame& frame) {
  Scan scan;
  scan.origin_C = frame.X_CS.translation();
  const Eigen::Matrix3f R_CS = frame.X_CS.linear().cast<float>();
  const Eigen::Vector3f t_CS = frame.X_CS.translation().cast<float>();
  auto& points = frame.points_S.points;
  std::size_t kept = 0;
  // A frame's points are read once, from memory, and waiting for them was most of this loop's time: each
  // 64-byte line is asked for 4 KB before it is read.
  constexpr std::size_t kAhead = 256;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (i % 4 == 0 && i + kAhead < points.size()) __builtin_prefetch(&points[i + kAhead]);
    const pcl::PointXYZ p = points[i];
    if (finite(p)) to_cell(R_CS, t_CS, p, points[kept++]);
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
