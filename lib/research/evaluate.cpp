// SPDX-License-Identifier: Apache-2.0
#include "cellmap/research/evaluate.hpp"

#include <algorithm>
#include <cmath>

#include "cellmap/boxes/volume.hpp"
#include "cellmap/common/error.hpp"

namespace cellmap::sim {
namespace {

// Half extents, in the cell frame, of the axis-aligned box around a solid with half extents h_O rotated by R.
Eigen::Vector3d aabb_half(const Eigen::Matrix3d& R, const Eigen::Vector3d& h_O) {
  return R.cwiseAbs() * h_O;
}

Eigen::Vector3d obstacle_half_extents(const Obstacle& o) {
  if (const auto* box = std::get_if<BoxShape>(&o.shape)) return box->half_extents;
  if (const auto* cyl = std::get_if<CylinderShape>(&o.shape))
    return {cyl->radius, cyl->radius, cyl->half_length};
  return Eigen::Vector3d::Constant(std::get<SphereShape>(o.shape).radius);
}

class VoxelGrid {
 public:
  VoxelGrid(const Region& region, double voxel) : region_(region), voxel_(voxel) {
    for (int i = 0; i < 3; ++i) {
      n_[i] = std::max(1, static_cast<int>(std::ceil((region.max[i] - region.min[i]) / voxel)));
    }
    flags_.assign(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2], 0);
  }

  // Sets `flag` on every voxel whose centre lies in the AABB (centre ± half) and satisfies inside(p).
  template <typename Inside>
  void mark(const Eigen::Vector3d& center, const Eigen::Vector3d& half, std::uint8_t flag,
            const Inside& inside) {
    int lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
      lo[i] =
          std::max(0, static_cast<int>(std::floor((center[i] - half[i] - region_.min[i]) / voxel_ - 0.5)));
      hi[i] = std::min(n_[i] - 1,
                       static_cast<int>(std::ceil((center[i] + half[i] - region_.min[i]) / voxel_ - 0.5)));
    }
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const Eigen::Vector3d p = region_.min + voxel_ * Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5);
          if (inside(p)) flags_[(static_cast<std::size_t>(z) * n_[1] + y) * n_[0] + x] |= flag;
        }
      }
    }
  }

  // Volume of the voxels whose flags, masked by `mask`, equal `value`.
  [[nodiscard]] double volume(std::uint8_t mask, std::uint8_t value) const {
    const auto count =
        std::count_if(flags_.begin(), flags_.end(), [&](std::uint8_t f) { return (f & mask) == value; });
    return static_cast<double>(count) * voxel_ * voxel_ * voxel_;
  }

 private:
  Region region_;
  double voxel_;
  int n_[3];
  std::vector<std::uint8_t> flags_;
};

constexpr std::uint8_t kObstacle = 1, kBox = 2;

std::vector<ObjectScore> score_objects(const std::vector<Obstacle>& obstacles, const std::vector<Box>& boxes,
                                       const Region& region) {
  std::vector<ObjectScore> objects;
  for (const Obstacle& o : obstacles) {
    if (!region.contains(o.X_CO.translation())) continue;
    ObjectScore score{o.name, 0.0, 0};
    const Box truth = tight_box(o);
    for (const Box& b : boxes) {
      const double iou = volume_iou(truth, b);
      if (iou > score.iou) score = {o.name, iou, b.id};
    }
    objects.push_back(score);
  }
  return objects;
}

}  // namespace

Box tight_box(const Obstacle& obstacle) {
  Box box;
  box.center = obstacle.X_CO.translation();
  box.half_extents = obstacle_half_extents(obstacle);
  box.rotation = Eigen::Quaterniond(obstacle.X_CO.linear()).normalized();
  return box;
}

double BoxScore::median_iou() const {
  if (objects.empty()) return 0.0;
  std::vector<double> iou;
  for (const ObjectScore& o : objects) iou.push_back(o.iou);
  std::sort(iou.begin(), iou.end());
  const std::size_t n = iou.size();
  return n % 2 ? iou[n / 2] : 0.5 * (iou[n / 2 - 1] + iou[n / 2]);
}

BoxScore score_boxes(const std::vector<Obstacle>& obstacles, const std::vector<Box>& boxes,
                     const Cloud& true_surface_C, const Region& region, double voxel, double tolerance) {
  if (!(voxel > 0)) throw Error("score_boxes: voxel must be positive");
  if (!(region.min.array() < region.max.array()).all()) throw Error("score_boxes: empty region");
  VoxelGrid grid(region, voxel);
  for (const Obstacle& o : obstacles) {
    const Eigen::Isometry3d X_OC = o.X_CO.inverse();
    Obstacle local = o;  // the same solid at the origin: voxels are moved into its frame once each
    local.X_CO = Eigen::Isometry3d::Identity();
    grid.mark(o.X_CO.translation(), aabb_half(o.X_CO.linear(), obstacle_half_extents(o)), kObstacle,
              [&](const Eigen::Vector3d& p_C) { return local.signed_distance(X_OC * p_C) <= 0; });
  }
  for (const Box& b : boxes) {
    grid.mark(b.center, aabb_half(b.rotation.toRotationMatrix(), b.half_extents), kBox,
              [&](const Eigen::Vector3d& p_C) { return b.contains(p_C); });
  }

  BoxScore score;
  score.boxes = boxes.size();
  score.true_volume = grid.volume(kObstacle, kObstacle);
  if (!(score.true_volume > 0)) throw Error("score_boxes: no obstacle volume inside the region");
  score.box_volume = grid.volume(kBox, kBox);
  score.lost_free_space = (score.box_volume - score.true_volume) / score.true_volume;
  score.blocked_free_space = grid.volume(kBox | kObstacle, kBox) / score.true_volume;
  score.volume_coverage = grid.volume(kBox | kObstacle, kBox | kObstacle) / score.true_volume;
  score.objects = score_objects(obstacles, boxes, region);

  std::size_t covered = 0;
  for (const pcl::PointXYZ& point : true_surface_C) {
    const Eigen::Vector3d p = point.getVector3fMap().cast<double>();
    if (!p.allFinite() || !region.contains(p)) continue;
    ++score.surface_points;
    covered +=
        std::any_of(boxes.begin(), boxes.end(), [&](const Box& b) { return b.contains(p, tolerance); });
  }
  score.coverage = score.surface_points ? static_cast<double>(covered) / score.surface_points : 0.0;
  return score;
}

}  // namespace cellmap::sim
