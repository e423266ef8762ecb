// SPDX-License-Identifier: Apache-2.0
#include "cellmap/research/evaluate.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap::sim {
namespace {

// A 0.4 × 0.2 × 0.2 block whose faces lie on the 1 cm voxel grid of the region, so volumes are exact.
Obstacle block() {
  Obstacle o{"block", BoxShape{Eigen::Vector3d(0.2, 0.1, 0.1)}, Eigen::Isometry3d::Identity()};
  o.X_CO.translation() = Eigen::Vector3d(0.5, 0.5, 0.3);
  return o;
}

Box box(const Eigen::Vector3d& center, const Eigen::Vector3d& half) {
  Box b;
  b.center = center;
  b.half_extents = half;
  return b;
}

Cloud surface_of(const Obstacle& o) {
  Cloud cloud;
  for (const Eigen::Vector3d& p : o.sample_surface(0.02)) cloud.push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return cloud;
}

const Region kRegion{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1)};

TEST(ScoreBoxesTest, ThePerfectBoxCoversEverythingAndLosesNothing) {
  const Obstacle o = block();
  const BoxScore s = score_boxes({o}, {box({0.5, 0.5, 0.3}, {0.2, 0.1, 0.1})}, surface_of(o), kRegion);
  EXPECT_NEAR(s.true_volume, 0.016, 1e-9);
  EXPECT_NEAR(s.box_volume, 0.016, 1e-9);
  EXPECT_NEAR(s.lost_free_space, 0.0, 1e-9);
  EXPECT_NEAR(s.blocked_free_space, 0.0, 1e-9);
  EXPECT_GT(s.surface_points, 100u);
  EXPECT_DOUBLE_EQ(s.coverage, 1.0);
  EXPECT_NEAR(s.volume_coverage, 1.0, 1e-9);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].name, "block");
  EXPECT_NEAR(s.objects[0].iou, 1.0, 1e-12);
  EXPECT_NEAR(s.median_iou(), 1.0, 1e-12);
}

TEST(ScoreBoxesTest, ABoxTwiceTheLengthLosesOneObjectVolume) {
  const Obstacle o = block();
  // Grown 0.4 m along x (to 0.8 m long): twice the object's volume, the extra half in free space.
  const BoxScore s = score_boxes({o}, {box({0.5, 0.5, 0.3}, {0.4, 0.1, 0.1})}, surface_of(o), kRegion);
  EXPECT_NEAR(s.lost_free_space, 1.0, 1e-9);
  EXPECT_NEAR(s.blocked_free_space, 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.coverage, 1.0);
  EXPECT_NEAR(s.volume_coverage, 1.0, 1e-9);
  EXPECT_NEAR(s.objects.at(0).iou, 0.5, 1e-12);
}

TEST(ScoreBoxesTest, AHalfBoxCoversHalfTheSurfaceAndOverlapsCountOnce) {
  const Obstacle o = block();
  // Only the x < 0.5 half, given twice: overlapping boxes count once.
  Box half = box({0.4, 0.5, 0.3}, {0.1, 0.1, 0.1});
  half.id = 4;
  const BoxScore s = score_boxes({o}, {half, half}, surface_of(o), kRegion);
  EXPECT_NEAR(s.box_volume, 0.008, 1e-9);
  EXPECT_NEAR(s.lost_free_space, -0.5, 1e-9);
  EXPECT_NEAR(s.coverage, 0.5, 0.05);
  EXPECT_NEAR(s.volume_coverage, 0.5, 1e-9);
  EXPECT_NEAR(s.objects.at(0).iou, 0.5, 1e-12);
  EXPECT_EQ(s.objects.at(0).box, 4u);
  EXPECT_THROW((void)score_boxes({}, {half}, surface_of(o), kRegion), Error);
}

TEST(ScoreBoxesTest, TightBoxesOfCylindersAndSpheresAreTheirCircumscribedBoxes) {
  Obstacle drum{"drum", CylinderShape{0.15, 0.2}, Eigen::Isometry3d::Identity()};
  drum.X_CO.translation() = Eigen::Vector3d(0.5, 0.5, 0.5);
  drum.X_CO.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Box tight = tight_box(drum);
  EXPECT_NEAR(tight.volume(), 0.3 * 0.3 * 0.4, 1e-12);
  EXPECT_NEAR(tight.rotation.angularDistance(Eigen::Quaterniond(drum.X_CO.linear())), 0.0, 1e-12);
  const BoxScore s = score_boxes({drum}, {tight}, surface_of(drum), kRegion);
  EXPECT_NEAR(s.objects.at(0).iou, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.coverage, 1.0);
  // The square prism around the round drum blocks 4/π − 1 of its volume (to the 1 cm grid).
  EXPECT_NEAR(s.blocked_free_space, 4.0 / M_PI - 1.0, 0.02);
  const Obstacle ball{"ball", SphereShape{0.1}, Eigen::Isometry3d::Identity()};
  EXPECT_NEAR(tight_box(ball).volume(), 0.008, 1e-12);
}

}  // namespace
}  // namespace cellmap::sim
