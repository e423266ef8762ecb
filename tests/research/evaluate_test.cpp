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
}

TEST(ScoreBoxesTest, ABoxTwiceTheLengthLosesOneObjectVolume) {
  const Obstacle o = block();
  // Grown 0.4 m along x (to 0.8 m long): twice the object's volume, the extra half in free space.
  const BoxScore s = score_boxes({o}, {box({0.5, 0.5, 0.3}, {0.4, 0.1, 0.1})}, surface_of(o), kRegion);
  EXPECT_NEAR(s.lost_free_space, 1.0, 1e-9);
  EXPECT_NEAR(s.blocked_free_space, 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.coverage, 1.0);
}

TEST(ScoreBoxesTest, AHalfBoxCoversHalfTheSurfaceAndOverlapsCountOnce) {
  const Obstacle o = block();
  // Only the x < 0.5 half, given twice: overlapping boxes count once.
  const Box half = box({0.4, 0.5, 0.3}, {0.1, 0.1, 0.1});
  const BoxScore s = score_boxes({o}, {half, half}, surface_of(o), kRegion);
  EXPECT_NEAR(s.box_volume, 0.008, 1e-9);
  EXPECT_NEAR(s.lost_free_space, -0.5, 1e-9);
  EXPECT_NEAR(s.coverage, 0.5, 0.05);
  EXPECT_THROW((void)score_boxes({}, {half}, surface_of(o), kRegion), Error);
}

}  // namespace
}  // namespace cellmap::sim
