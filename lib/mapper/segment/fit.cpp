#include "cellmap/segment/fit.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <limits>
#include <utility>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

// The extent of the points along the axes R (columns, in the points' frame), as low and high corners.
std::pair<Eigen::Vector3d, Eigen::Vector3d> extent_along(const Cloud& cloud, const std::vector<int>& indices,
                                                         const Eigen::Matrix3d& R) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (int i : indices) {
    const Eigen::Vector3d p_B = R.transpose() * cloud[i].getVector3fMap().cast<double>();
    low = low.cwiseMin(p_B);
    high = high.cwiseMax(p_B);
  }
  return {low, high};
}

// The box with axes R that holds all points, as centre and half extents.
Box enclose(const Cloud& cloud, const std::vector<int>& indices, const Eigen::Matrix3d& R) {
  const auto [low, high] = extent_along(cloud, indices, R);
  Box box;
  box.center = R * (0.5 * (low + high));
  box.half_extents = (0.5 * (high - low)).array() + kBoxFitSlack;
  box.rotation = Eigen::Quaterniond(R).normalized();
  box.points = indices.size();
  return box;
}

double volume_with_axes(const Cloud& cloud, const std::vector<int>& indices, const Eigen::Matrix3d& R) {
  const auto [low, high] = extent_along(cloud, indices, R);
  return (high - low).prod();
}

// Principal axes of a partly seen object are tilted (three visible faces of a box skew the covariance), so
// the PCA rotation is refined by turning it about each of its axes to the smallest volume: a coarse then a
// fine sweep, on at most 2000 evenly spread points. Hand-written: neither Eigen nor PCL offers a
// minimum-volume box (PCL's MomentOfInertiaEstimation is PCA as well, and slow).
Eigen::Matrix3d refine_axes(const Cloud& cloud, const std::vector<int>& indices, Eigen::Matrix3d R) {
  std::vector<int> sample;
  const std::size_t stride = std::max<std::size_t>(1, indices.size() / 2000);
  for (std::size_t i = 0; i < indices.size(); i += stride) sample.push_back(indices[i]);
  double best = volume_with_axes(cloud, sample, R);
  constexpr double kDegree = 3.14159265358979323846 / 180.0;
  for (const auto& [range, step] : {std::pair<double, double>{45.0, 3.0}, {3.0, 0.5}}) {
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Matrix3d best_R = R;
      for (double angle = -range; angle <= range + 1e-9; angle += step) {
        if (angle == 0.0) continue;
        const Eigen::Matrix3d candidate =
            R * Eigen::AngleAxisd(angle * kDegree, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
        const double volume = volume_with_axes(cloud, sample, candidate);
        if (volume < best) {
          best = volume;
          best_R = candidate;
        }
      }
      R = best_R;
    }
  }
  return R;
}

}  // namespace

BoxKind box_kind_from_string(const std::string& text, const std::string& what) {
  if (text == "aabb") return BoxKind::kAxisAligned;
  if (text == "obb") return BoxKind::kOriented;
  throw Error(what + ": must be 'obb' or 'aabb', got '" + text + "'");
}

const char* to_string(BoxKind kind) {
  return kind == BoxKind::kAxisAligned ? "aabb" : "obb";
}

Box fit_box(const Cloud& cloud, const std::vector<int>& indices, BoxKind kind) {
  if (indices.empty()) throw Error("fit_box: no points");
  for (int i : indices) {
    if (i < 0 || static_cast<std::size_t>(i) >= cloud.size())
      throw Error("fit_box: point index out of range");
  }
  Box aabb = enclose(cloud, indices, Eigen::Matrix3d::Identity());
  aabb.rotation = Eigen::Quaterniond::Identity();
  if (kind == BoxKind::kAxisAligned || indices.size() < 3) return aabb;

  // Covariance about the AABB centre, which keeps float coordinates of a few metres from cancelling.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i : indices) {
    const Eigen::Vector3d d = cloud[i].getVector3fMap().cast<double>() - aabb.center;
    mean += d;
    scatter.noalias() += d * d.transpose();
  }
  const double n = static_cast<double>(indices.size());
  mean /= n;
  const Eigen::Matrix3d covariance = scatter / n - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  if (solver.info() != Eigen::Success) return aabb;
  // Largest variance first, third axis from the cross product: a proper rotation (det = +1).
  Eigen::Matrix3d R;
  R.col(0) = solver.eigenvectors().col(2).normalized();
  R.col(1) = solver.eigenvectors().col(1).normalized();
  R.col(2) = R.col(0).cross(R.col(1)).normalized();
  R.col(1) = R.col(2).cross(R.col(0));
  const Box obb = enclose(cloud, indices, refine_axes(cloud, indices, R));
  return obb.volume() < aabb.volume() ? obb : aabb;
}

}  // namespace cellmap
