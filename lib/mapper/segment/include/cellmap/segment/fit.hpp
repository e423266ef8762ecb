// SPDX-License-Identifier: Apache-2.0
#pragma once
// Fitting a box around a set of points.

#include <Eigen/Core>

#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/frame/cloud.hpp"

namespace cellmap {

/// Axis-aligned (rotation identity, "aabb"), oriented along the principal axes of the points (the paper's
/// object-aligned box, "pca"), or the oriented box of (near) minimum volume ("obb").
enum class BoxKind { kAxisAligned, kPrincipalAxes, kOriented };

/// "aabb" / "pca" / "obb". @throws Error naming `what` for any other text.
[[nodiscard]] BoxKind box_kind_from_string(const std::string& text, const std::string& what = "box kind");
[[nodiscard]] const char* to_string(BoxKind kind);

/// Half extents are grown by this much (metres) so that the extreme points stay inside under the rounding of
/// a containment test in the caller's own arithmetic (coverage is a safety property).
inline constexpr double kBoxFitSlack = 1e-6;

/// The smallest box of the requested kind, in the points' frame, that contains every point
/// `cloud[indices[i]]`, with `points` = indices.size() and id 0. Rotations are proper (right-handed).
/// With `cube` > 0 each point stands for the axis-aligned cube of that edge around it (e.g. an occupied
/// voxel around its centre): the box holds every cube whole, and the volumes compared are those of the grown
/// boxes.
/// - Principal axes: the eigenvectors of the points' covariance (Eigen SelfAdjointEigenSolver), extents from
///   the points projected on them. Two passes over the points. Not always smaller than the axis-aligned box
///   (e.g. a cube seen as three faces skews the covariance).
/// - Oriented: the convex hull of the points (qhull) gives candidate face normals: its facet directions
///   (grouped within about 1°) covering the most area (24), the principal and the frame's axes; for each,
///   the minimum-area rectangle of the hull projected on its plane (rotating calipers) gives the smallest box
///   with a face of that normal; the best ones are polished by a local rotation search (see
///   segment/minimum_volume.hpp). Exact whenever the minimum-volume box has a face flush with one of those
///   directions (a box, a prism standing on a face, seen from any side); never larger than the
///   principal-axes or the axis-aligned box. Cost: the hull (O(n log n)) plus O(h log h) per candidate for h
///   hull vertices.
/// @throws Error if `indices` is empty or an index is out of range.
[[nodiscard]] Box fit_box(const Cloud& cloud, const std::vector<int>& indices, BoxKind kind,
                          double cube = 0.0);
/// As above, for points given as a list. The box of a set's hull vertices (hull_vertices) equals the box of
/// the set for kAxisAligned and kOriented, so merging boxes can fit hulls instead of all points.
/// @throws Error if `points` is empty.
[[nodiscard]] Box fit_box(const std::vector<Eigen::Vector3d>& points, BoxKind kind, double cube = 0.0);

/// The vertices of the points' convex hull (qhull), or all points when they span no volume (flat,
/// collinear, fewer than 5).
[[nodiscard]] std::vector<Eigen::Vector3d> hull_vertices(const std::vector<Eigen::Vector3d>& points);

/// Grows `box` so that the axis-aligned cube of edge `edge` around every point it held fits inside: each
/// half extent by edge / 2 · ‖axis‖₁ (a cube's half extent along a unit axis a is edge / 2 · ‖a‖₁).
void grow_to_hold_cubes(Box& box, double edge);

}  // namespace cellmap
