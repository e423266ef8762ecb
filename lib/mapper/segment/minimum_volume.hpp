// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal to box fitting: the axes of the minimum-volume box around a point set.

#include <Eigen/Core>

#include <vector>

namespace cellmap::detail {

/// A direction a box face may lie flush with, and how much hull surface faces that way (m²).
struct FaceDirection final {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double area = 0;
};

/// The vertices of the convex hull of `points` (qhull), or all points when they span no volume (flat,
/// collinear or fewer than 5): the extents of a point set along any direction are those of its hull. With
/// `faces`, also the hull's facet normals grouped within about 1° (area-weighted mean normal and summed
/// area per group, largest area first).
[[nodiscard]] std::vector<Eigen::Vector3d> hull_vertices(const std::vector<Eigen::Vector3d>& points,
                                                         std::vector<FaceDirection>* faces);

/// Axes (columns of a proper rotation R_CB) of the smallest box around `points` among the boxes with a face
/// perpendicular to one of `normals` (for each normal, the minimum-area rectangle of the points projected on
/// its plane, by rotating calipers), the 12 best of them polished by a local rotation search (turns about
/// the box's axes by 3° down to 0.05° while the volume shrinks). With the hull's facet normals this is the
/// exact minimum whenever the minimum box has a face flush with a hull facet (every box and every prism
/// standing on a face); otherwise (O'Rourke 1985: two adjacent faces then each touch a hull edge) the search
/// ends near it: on random blobs, the hard case, never larger than the best of 20 000 random rotations
/// (tests/boxes/fit_test.cpp). Volumes are compared with `padding` (metres) added to every edge,
/// so that among flat point sets the smallest rectangle still wins.
[[nodiscard]] Eigen::Matrix3d minimum_volume_axes(const std::vector<Eigen::Vector3d>& points,
                                                  const std::vector<Eigen::Vector3d>& normals,
                                                  double padding);

/// Volume of the box with axes R around `points`.
[[nodiscard]] double volume_along(const std::vector<Eigen::Vector3d>& points, const Eigen::Matrix3d& R);

}  // namespace cellmap::detail
