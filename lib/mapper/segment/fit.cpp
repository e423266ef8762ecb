// SPDX-License-Identifier: Apache-2.0
#include "cellmap/segment/fit.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <limits>
#include <optional>
#include <utility>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "minimum_volume.hpp"

namespace cellmap {
namespace {

using Points = std::vector<Eigen::Vector3d>;

// The box with axes R (columns, in the points' frame) that holds all points and their cubes.
Box enclose(const Points& points, const Eigen::Matrix3d& R, double cube) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d p_B = R.transpose() * p;
    low = low.cwiseMin(p_B);
    high = high.cwiseMax(p_B);
  }
  Box box;
  box.center = R * (0.5 * (low + high));
  box.half_extents = (0.5 * (high - low)).array() + kBoxFitSlack;
  box.rotation = Eigen::Quaterniond(R).normalized();
  box.points = points.size();
  grow_to_hold_cubes(box, cube);
  return box;
}

// Principal axes of the points' covariance, largest variance first, as a proper rotation.
std::optional<Eigen::Matrix3d> principal_axes(const Points& points, const Eigen::Vector3d& origin) {
  // Covariance about a nearby origin, which keeps coordinates of a few metres from cancelling.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d d = p - origin;
    mean += d;
    scatter.noalias() += d * d.transpose();
  }
  const double n = static_cast<double>(points.size());
  mean /= n;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter / n - mean * mean.transpose());
  if (solver.info() != Eigen::Success) return std::nullopt;
  Eigen::Matrix3d R;
  R.col(0) = solver.eigenvectors().col(2).normalized();
  R.col(1) = solver.eigenvectors().col(1).normalized();
  R.col(2) = R.col(0).cross(R.col(1)).normalized();
  R.col(1) = R.col(2).cross(R.col(0));
  return R;
}

// The minimum-volume axes, searched on the hull's vertices (they have the same extents as all points). The
// candidate face normals: the hull's facet directions (grouped within about 1°) covering the most area, the
// principal axes and the frame's axes.
Eigen::Matrix3d minimum_volume_axes(const Points& points, const Eigen::Matrix3d& principal, double cube) {
  constexpr std::size_t kDirections = 24;
  std::vector<detail::FaceDirection> faces;
  const Points hull = detail::hull_vertices(points, &faces);
  std::vector<Eigen::Vector3d> normals;
  for (std::size_t f = 0; f < std::min(faces.size(), kDirections); ++f) normals.push_back(faces[f].normal);
  for (int axis = 0; axis < 3; ++axis) {
    normals.push_back(principal.col(axis));
    normals.push_back(Eigen::Vector3d::Unit(axis));
  }
  return detail::minimum_volume_axes(hull, normals, 2 * kBoxFitSlack + cube);
}

}  // namespace

BoxKind box_kind_from_string(const std::string& text, const std::string& what) {
  if (text == "aabb") return BoxKind::kAxisAligned;
  if (text == "pca") return BoxKind::kPrincipalAxes;
  if (text == "obb") return BoxKind::kOriented;
  throw Error(what + ": must be 'obb', 'pca' or 'aabb', got '" + single_line(text) + "'");
}

const char* to_string(BoxKind kind) {
  switch (kind) {
    case BoxKind::kAxisAligned:
      return "aabb";
    case BoxKind::kPrincipalAxes:
      return "pca";
    case BoxKind::kOriented:
      break;
  }
  return "obb";
}

void grow_to_hold_cubes(Box& box, double edge) {
  if (!(edge > 0)) return;
  const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
  for (int axis = 0; axis < 3; ++axis) box.half_extents[axis] += 0.5 * edge * R.col(axis).lpNorm<1>();
}

std::vector<Eigen::Vector3d> hull_vertices(const std::vector<Eigen::Vector3d>& points) {
  return detail::hull_vertices(points, nullptr);
}

Box fit_box(const std::vector<Eigen::Vector3d>& points, BoxKind kind, double cube) {
  if (points.empty()) throw Error("fit_box: no points");
  const Box aabb = enclose(points, Eigen::Matrix3d::Identity(), cube);
  if (kind == BoxKind::kAxisAligned || points.size() < 3) return aabb;
  const std::optional<Eigen::Matrix3d> principal = principal_axes(points, aabb.center);
  if (!principal) return aabb;
  const Box pca = enclose(points, *principal, cube);
  if (kind == BoxKind::kPrincipalAxes) return pca;
  const Box obb = enclose(points, minimum_volume_axes(points, *principal, cube), cube);
  const Box& smaller = pca.volume() < aabb.volume() ? pca : aabb;
  return obb.volume() < smaller.volume() ? obb : smaller;
}

Box fit_box(const Cloud& cloud, const std::vector<int>& indices, BoxKind kind, double cube) {
  if (indices.empty()) throw Error("fit_box: no points");
  std::vector<Eigen::Vector3d> points;
  points.reserve(indices.size());
  for (int i : indices) {
    if (i < 0 || static_cast<std::size_t>(i) >= cloud.size())
      throw Error("fit_box: point index out of range");
    points.push_back(cloud[i].getVector3fMap().cast<double>());
  }
  return fit_box(points, kind, cube);
}

}  // namespace cellmap
