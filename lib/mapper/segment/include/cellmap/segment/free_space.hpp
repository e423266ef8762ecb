// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the sensor saw to be free around a group of points: the measure behind splitting and merging boxes.

#include <Eigen/Core>

#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/frame/cloud.hpp"

namespace cellmap {

/// The space around a group of points (one segment, one object) as a sensor at `viewpoint` saw it. A place is
/// free when it lies in front of every point of the group in its direction (nearer to the viewpoint by more
/// than `margin`), or when no point of the group lies in its direction. Space the group hides, behind its
/// own surface (an object's inside, its hidden sides and underside), is not free: a box over it may well hold
/// the object, so cutting it away saves nothing certain. Space only other objects hide counts as free: it
/// judges this group's boxes, not the scene.
///
/// Directions are binned in a pinhole projection about the group's mean direction (bins `angular_step`
/// radians wide on the axis); each bin keeps the range of its nearest point, and a bin no point fell into
/// takes the nearest of its 8 neighbours, so a surface sampled about one bin apart hides what is behind it.
/// Points more than about 84° off the mean direction are left out. Immutable after construction; const
/// members are thread-safe.
class SeenFreeSpace final {
 public:
  /// `indices` into `cloud` (cloud frame); `viewpoint` = the sensor origin in that frame; `angular_step` > 0
  /// radians, about the angle between neighbouring points; `margin` >= 0 metres, the thickness of a surface
  /// (noise, voxel): places less than that in front of it are not free. @throws Error on invalid values.
  SeenFreeSpace(const Cloud& cloud, const std::vector<int>& indices, const Eigen::Vector3d& viewpoint,
                double angular_step, double margin);

  [[nodiscard]] bool is_free(const Eigen::Vector3d& p) const;
  /// Free volume inside `box`, m³: the box's volume times the share of free cell centres on a grid of at most
  /// about `samples` cells (its cells are near cubes; a flat box gets one layer). Cost: one is_free per cell.
  [[nodiscard]] double free_volume(const Box& box, int samples = 1024) const;

 private:
  friend double free_volume(const Box& box, const std::vector<const SeenFreeSpace*>& views, int samples);
  [[nodiscard]] bool project(const Eigen::Vector3d& p, int& column, int& row, double& range) const;

  Eigen::Vector3d viewpoint_;
  Eigen::Matrix3d axes_;  // rows: the projection's right, down and forward directions
  double step_ = 0, margin_ = 0;
  double u0_ = 0, v0_ = 0;  // tangent coordinates of bin (0, 0)'s corner
  int columns_ = 0, rows_ = 0;
  std::vector<float> nearest_;  // per bin: range of the nearest point shading it, +inf = none
};

/// Free volume inside `box` around several groups at once: a place is free when every one of `views` sees it
/// free (together the groups hide what any of them hides), on the grid of SeenFreeSpace::free_volume. Up to
/// the direction bins, the same as one SeenFreeSpace of all their points, without building it.
[[nodiscard]] double free_volume(const Box& box, const std::vector<const SeenFreeSpace*>& views,
                                 int samples = 1024);

}  // namespace cellmap
