#include "cellmap/preprocess/workspace.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

TEST(Workspace, BoxCropsToItsRange) {
  const Workspace w = Workspace::box({0, 0, 0}, {1, 2, 3});
  Cloud cloud;
  cloud.push_back({0.5f, 1.0f, 1.0f});   // in
  cloud.push_back({1.5f, 1.0f, 1.0f});   // out in x
  cloud.push_back({0.0f, 2.0f, 3.0f});   // on the corner: in
  cloud.push_back({0.5f, -0.1f, 1.0f});  // out in y
  EXPECT_EQ(crop_to_workspace(cloud, w), (std::vector<int>{0, 2}));
  EXPECT_THROW((void)Workspace::box({1, 0, 0}, {0, 1, 1}), Error);
}

TEST(Workspace, VoxelSetCoversEverythingWithinTheEnvelope) {
  // Samples along a line (like a tool path); the envelope is 0.1 m.
  std::vector<Eigen::Vector3d> samples;
  for (int i = 0; i <= 10; ++i) samples.emplace_back(0.1 * i, 0.0, 0.5);
  const Workspace w = Workspace::from_points(samples, 0.1, 0.05);
  EXPECT_FALSE(w.is_box());
  EXPECT_GT(w.voxel_count(), 0u);
  // Every point within the envelope of a sample is inside.
  for (double x = -0.09; x <= 1.09; x += 0.01) {
    for (double dy : {-0.099, 0.0, 0.07}) EXPECT_TRUE(w.contains({x, dy, 0.5})) << x << " " << dy;
  }
  EXPECT_TRUE(w.contains({0.5, 0.0, 0.599}));
  // Far away points are outside (the voxels reach at most envelope + one voxel diagonal).
  EXPECT_FALSE(w.contains({0.5, 0.3, 0.5}));
  EXPECT_FALSE(w.contains({1.4, 0.0, 0.5}));
  EXPECT_FALSE(w.contains({0.5, 0.0, 0.0}));
  EXPECT_THROW((void)Workspace::from_points({}, 0.1, 0.05), Error);
  EXPECT_THROW((void)Workspace::from_points(samples, 0.1, 0.0), Error);
}

}  // namespace
}  // namespace cellmap
