// SPDX-License-Identifier: Apache-2.0
#include "cellmap/segment/free_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

constexpr double kMinForward = 0.1;  // cos of the largest angle off the mean direction that is binned (~84°)
constexpr std::size_t kMaxBins = 4u << 20;

}  // namespace

SeenFreeSpace::SeenFreeSpace(const Cloud& cloud, const std::vector<int>& indices,
                             const Eigen::Vector3d& viewpoint, double angular_step, double margin)
    : viewpoint_(viewpoint), step_(angular_step), margin_(margin) {
  if (!(angular_step > 0) || !(margin >= 0) || !viewpoint.allFinite()) {
    throw Error("free space: angular_step must be > 0, margin >= 0 and the viewpoint finite");
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : indices) mean += (cloud[i].getVector3fMap().cast<double>() - viewpoint).normalized();
  const Eigen::Vector3d forward = mean.norm() > 0 ? mean.normalized() : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d other =
      std::abs(forward.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d right = forward.cross(other).normalized();
  axes_.row(0) = right;
  axes_.row(1) = forward.cross(right);
  axes_.row(2) = forward;

  // Tangent coordinates of the points, their extent, then the bins.
  std::vector<Eigen::Vector3d> projected;  // u, v, range
  projected.reserve(indices.size());
  double u_min = std::numeric_limits<double>::infinity(), v_min = u_min, u_max = -u_min, v_max = -u_min;
  for (int i : indices) {
    const Eigen::Vector3d d = axes_ * (cloud[i].getVector3fMap().cast<double>() - viewpoint);
    const double range = d.norm();
    if (!(d.z() > kMinForward * range)) continue;
    projected.emplace_back(d.x() / d.z(), d.y() / d.z(), range);
    u_min = std::min(u_min, projected.back().x()), u_max = std::max(u_max, projected.back().x());
    v_min = std::min(v_min, projected.back().y()), v_max = std::max(v_max, projected.back().y());
  }
  if (projected.empty()) return;
  // Coarser bins when the group spans a wide angle, so the image stays bounded.
  while ((u_max - u_min) / step_ * (v_max - v_min) / step_ > static_cast<double>(kMaxBins)) step_ *= 2;
  u0_ = u_min - 2 * step_;
  v0_ = v_min - 2 * step_;
  columns_ = static_cast<int>(std::ceil((u_max - u0_) / step_)) + 3;
  rows_ = static_cast<int>(std::ceil((v_max - v0_) / step_)) + 3;
  std::vector<float> own(static_cast<std::size_t>(columns_) * rows_, std::numeric_limits<float>::infinity());
  for (const Eigen::Vector3d& p : projected) {
    const int c = static_cast<int>((p.x() - u0_) / step_), r = static_cast<int>((p.y() - v0_) / step_);
    float& bin = own[static_cast<std::size_t>(r) * columns_ + c];
    bin = std::min(bin, static_cast<float>(p.z()));
  }
  // A bin no point fell into takes the nearest of its 8 neighbours: sampling gaps in a surface do not let
  // free space through, while bins with a point keep their own range (a min over neighbours would shade
  // space above a surface seen at a grazing angle).
  nearest_ = own;
  for (int r = 1; r + 1 < rows_; ++r) {
    for (int c = 1; c + 1 < columns_; ++c) {
      float& bin = nearest_[static_cast<std::size_t>(r) * columns_ + c];
      if (std::isfinite(bin)) continue;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -1; dc <= 1; ++dc)
          bin = std::min(bin, own[static_cast<std::size_t>(r + dr) * columns_ + c + dc]);
      }
    }
  }
}

bool SeenFreeSpace::project(const Eigen::Vector3d& p, int& column, int& row, double& range) const {
  const Eigen::Vector3d d = axes_ * (p - viewpoint_);
  range = d.norm();
  if (!(d.z() > kMinForward * range)) return false;
  const double c = (d.x() / d.z() - u0_) / step_, r = (d.y() / d.z() - v0_) / step_;
  if (!(c >= 0 && r >= 0 && c < columns_ && r < rows_)) return false;
  column = static_cast<int>(c);
  row = static_cast<int>(r);
  return true;
}

bool SeenFreeSpace::is_free(const Eigen::Vector3d& p) const {
  int column = 0, row = 0;
  double range = 0;
  if (!project(p, column, row, range)) return true;
  return range < static_cast<double>(nearest_[static_cast<std::size_t>(row) * columns_ + column]) - margin_;
}

double SeenFreeSpace::free_volume(const Box& box, int samples) const {
  return cellmap::free_volume(box, {this}, samples);
}

double free_volume(const Box& box, const std::vector<const SeenFreeSpace*>& views, int samples) {
  const double volume = box.volume();
  if (!(volume > 0) || samples < 1) return 0.0;
  const Eigen::Vector3d size = 2 * box.half_extents;
  // Near-cubic cells of about volume / samples; a thin side gets a single layer.
  double cell = std::cbrt(volume / samples);
  Eigen::Vector3i n;
  for (int attempt = 0; attempt < 40; ++attempt) {
    for (int axis = 0; axis < 3; ++axis)
      n[axis] = std::max(1, static_cast<int>(std::round(size[axis] / cell)));
    if (static_cast<double>(n.prod()) <= 2.0 * samples) break;
    cell *= 1.25;
  }
  const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
  int free = 0;
  for (int i = 0; i < n.x(); ++i) {
    for (int j = 0; j < n.y(); ++j) {
      for (int k = 0; k < n.z(); ++k) {
        const Eigen::Vector3d unit((i + 0.5) / n.x() - 0.5, (j + 0.5) / n.y() - 0.5, (k + 0.5) / n.z() - 0.5);
        const Eigen::Vector3d p = box.center + R * unit.cwiseProduct(size);
        free +=
            std::all_of(views.begin(), views.end(), [&](const SeenFreeSpace* v) { return v->is_free(p); });
      }
    }
  }
  return volume * free / static_cast<double>(n.prod());
}

}  // namespace cellmap
