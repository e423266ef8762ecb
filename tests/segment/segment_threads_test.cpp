// SPDX-License-Identifier: Apache-2.0
// The re-segmentation's stages split over threads give the same result on any number of them (a program of
// its own: the ThreadSanitizer pass of CI runs it).
#include <gtest/gtest.h>

#include <cmath>

#include "cellmap/preprocess/neighbourhoods.hpp"
#include "cellmap/segment/box_split.hpp"
#include "scenes.hpp"

namespace cellmap {
namespace {

const Eigen::Matrix3d kI = Eigen::Matrix3d::Identity();

TEST(SegmentThreadsTest, NeighbourhoodsAreTheSameOnAnyNumberOfThreads) {
  Cloud cloud;  // a wavy 60 × 40 sheet: 2 400 points, enough for 3 threads
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 40; ++j) cloud.push_back({0.01f * i, 0.01f * j, 1.0f + 0.02f * std::sin(0.3f * i)});
  }
  const Neighbourhoods one = compute_neighbourhoods(cloud, 12, true, Eigen::Vector3f::Zero(), 1);
  for (const int threads : {2, 3}) {
    const Neighbourhoods split = compute_neighbourhoods(cloud, 12, true, Eigen::Vector3f::Zero(), threads);
    EXPECT_EQ(split.indices, one.indices) << threads;
    EXPECT_EQ(split.sq_distances, one.sq_distances) << threads;
    EXPECT_EQ(split.mean_distance, one.mean_distance) << threads;
    EXPECT_EQ(split.normals, one.normals) << threads;
    EXPECT_EQ(split.curvature, one.curvature) << threads;
  }
}

TEST(SegmentThreadsTest, SegmentsSplitOnThreadsGetTheSameLabels) {
  // Three segments (a post on a plate, a table with pallets, a lone box), split on 1, 2 and 3 threads.
  test::Scene scene(Eigen::Vector3f(0.0f, 0.0f, 1.6f));
  scene.add_box({-1.0, 0, 0.025}, {0.25, 0.15, 0.025}, kI);
  scene.add_box({-0.9, 0, 0.2}, {0.04, 0.04, 0.15}, kI);
  scene.add_box({0, 0, -0.02}, {0.5, 0.4, 0.02}, kI);
  scene.add_box({-0.3, -0.2, 0.07}, {0.15, 0.12, 0.07}, kI);
  scene.add_box({0.3, 0.2, 0.07}, {0.15, 0.12, 0.07}, kI);
  scene.add_box({1.0, 0, 0.1}, {0.15, 0.1, 0.1}, kI);
  Segments segments;
  segments.count = 3;
  for (int object : scene.object) segments.label.push_back(object <= 2 ? 0 : object <= 5 ? 1 : 2);
  const Neighbourhoods nb = compute_neighbourhoods(scene.points, 12, false);
  std::size_t one_count = 0;
  const Segments one = split_by_free_space(scene.points, nb, segments, scene.viewpoint().cast<double>(),
                                           test::split_params(), &one_count);
  EXPECT_EQ(one_count, 2u);  // the post off its plate, the pallets off their table; the lone box stays
  EXPECT_EQ(one.count, 6);
  for (const int threads : {2, 3}) {
    BoxSplitParams on_threads = test::split_params();
    on_threads.threads = threads;
    std::size_t count = 0;
    const Segments split =
        split_by_free_space(scene.points, nb, segments, scene.viewpoint().cast<double>(), on_threads, &count);
    EXPECT_EQ(split.label, one.label) << threads;
    EXPECT_EQ(split.count, one.count) << threads;
    EXPECT_EQ(count, one_count) << threads;
  }
}

}  // namespace
}  // namespace cellmap
