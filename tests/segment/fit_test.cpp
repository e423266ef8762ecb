#include "cellmap/segment/fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

// Points on all six faces of a box with half extents `half`, rotated by R_CB and centred at p_CB (grid step 1
// cm).
Cloud box_surface(const Eigen::Vector3d& p_CB, const Eigen::Vector3d& half, const Eigen::Matrix3d& R_CB) {
  Cloud cloud;
  const double step = 0.01;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (double sign : {-1.0, 1.0}) {
      for (double a = -half[u]; a <= half[u] + 1e-9; a += step) {
        for (double b = -half[v]; b <= half[v] + 1e-9; b += step) {
          Eigen::Vector3d p_B;
          p_B[axis] = sign * half[axis];
          p_B[u] = a;
          p_B[v] = b;
          const Eigen::Vector3f p_C = (p_CB + R_CB * p_B).cast<float>();
          cloud.push_back({p_C.x(), p_C.y(), p_C.z()});
        }
      }
    }
  }
  return cloud;
}

std::vector<int> all(const Cloud& cloud) {
  std::vector<int> indices(cloud.size());
  std::iota(indices.begin(), indices.end(), 0);
  return indices;
}

TEST(FitBox, ObbOfARotatedBoxRecoversItsAxesAndExtents) {
  const Eigen::Matrix3d R_CB =
      (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Vector3d half(0.3, 0.15, 0.05);
  const Eigen::Vector3d p_CB(1.0, -0.5, 0.4);
  const Cloud cloud = box_surface(p_CB, half, R_CB);
  const Box box = fit_box(cloud, all(cloud), BoxKind::kOriented);
  EXPECT_EQ(box.points, cloud.size());
  EXPECT_NEAR((box.center - p_CB).norm(), 0.0, 1e-5);
  // Largest spread first: the box's axes are the true axes up to sign.
  const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
  EXPECT_NEAR(R.determinant(), 1.0, 1e-9);  // right-handed
  EXPECT_NEAR(box.rotation.norm(), 1.0, 1e-12);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(std::abs(R.col(axis).dot(R_CB.col(axis))), 1.0, 1e-6) << axis;
    EXPECT_NEAR(box.half_extents[axis], half[axis], 1e-5) << axis;
  }
  for (const auto& p : cloud) EXPECT_TRUE(box.contains(p.getVector3fMap().cast<double>()));
}

TEST(FitBox, ObbIsSmallerThanAabbOnARotatedObjectAndBothHoldEveryPoint) {
  const Eigen::Matrix3d R_CB = Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Cloud cloud = box_surface({0.2, 0.1, 0.3}, {0.25, 0.1, 0.1}, R_CB);
  const Box obb = fit_box(cloud, all(cloud), BoxKind::kOriented);
  const Box aabb = fit_box(cloud, all(cloud), BoxKind::kAxisAligned);
  EXPECT_TRUE(aabb.is_axis_aligned());
  EXPECT_LT(obb.volume(), 0.7 * aabb.volume());
  for (const auto& p : cloud) {
    EXPECT_TRUE(obb.contains(p.getVector3fMap().cast<double>()));
    EXPECT_TRUE(aabb.contains(p.getVector3fMap().cast<double>()));
  }
}

TEST(FitBox, ObbNeverExceedsTheAabb) {
  // A cube's PCA axes are arbitrary; the fit must fall back to the axis-aligned box when that is smaller.
  const Cloud cloud = box_surface({0, 0, 0}, {0.1, 0.1, 0.1}, Eigen::Matrix3d::Identity());
  const Box obb = fit_box(cloud, all(cloud), BoxKind::kOriented);
  const Box aabb = fit_box(cloud, all(cloud), BoxKind::kAxisAligned);
  EXPECT_LE(obb.volume(), aabb.volume());
  EXPECT_NEAR(aabb.half_extents.x(), 0.1, 1e-5);
}

TEST(FitBox, SubsetsAndDegenerateInput) {
  Cloud cloud;
  cloud.push_back({1.0f, 2.0f, 3.0f});
  cloud.push_back({5.0f, 5.0f, 5.0f});
  const Box point = fit_box(cloud, {0}, BoxKind::kOriented);
  EXPECT_NEAR((point.center - Eigen::Vector3d(1, 2, 3)).norm(), 0.0, 1e-6);
  EXPECT_LE(point.half_extents.maxCoeff(), 2 * kBoxFitSlack);
  EXPECT_TRUE(point.contains({1, 2, 3}));
  EXPECT_THROW((void)fit_box(cloud, {}, BoxKind::kOriented), Error);
  EXPECT_THROW((void)fit_box(cloud, {2}, BoxKind::kOriented), Error);
  EXPECT_EQ(box_kind_from_string("aabb"), BoxKind::kAxisAligned);
  EXPECT_THROW((void)box_kind_from_string("sphere"), Error);
}

}  // namespace
}  // namespace cellmap
