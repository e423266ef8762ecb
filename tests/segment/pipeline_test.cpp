// SPDX-License-Identifier: Apache-2.0
#include "cellmap/segment/pipeline.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "cellmap/common/error.hpp"
#include "scenes.hpp"
#include "support/test_support.hpp"

namespace cellmap {
namespace {

using Footprint = std::pair<Eigen::Vector2d, Eigen::Vector2d>;

// A 10 cm cube and a 12 x 9 x 8 cm box turned by 30° standing apart on a floor, seen obliquely from above.
// (A turned cube would not do for the OBB check: a cube's covariance is isotropic, so its principal axes are
// arbitrary and the fit falls back to the axis-aligned box.)
test::Scene two_cubes_on_a_floor() {
  test::Scene scene(Eigen::Vector3f(0.1f, -0.7f, 0.8f));
  scene.add_box({-0.12, 0.0, 0.05}, {0.05, 0.05, 0.05}, Eigen::Matrix3d::Identity());
  scene.add_box({0.12, 0.05, 0.04}, {0.06, 0.045, 0.04},
                Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitZ()).toRotationMatrix());
  // The turned cube's footprint is approximated by its bounding square (the floor under it is hidden anyway).
  scene.add_floor(0.3, {Footprint({-0.17, -0.05}, {-0.07, 0.05}), Footprint({0.05, -0.02}, {0.19, 0.12})});
  return scene;
}

// For every object: how many of its points were fitted to each box.
std::map<int, std::map<int, int>> boxes_per_object(const test::Scene& scene, const SegmentResult& result) {
  std::map<int, std::map<int, int>> boxes;
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    if (result.box_of_point[i] >= 0) ++boxes[scene.object[i]][result.box_of_point[i]];
  }
  return boxes;
}

// The box holding most of `object`'s points, and the share of its points it holds.
std::pair<int, double> main_box(const std::map<int, std::map<int, int>>& boxes, int object) {
  std::pair<int, int> best{-1, 0};
  int total = 0;
  for (const auto& [box, n] : boxes.at(object)) {
    total += n;
    if (n > best.second) best = {box, n};
  }
  return {best.first, static_cast<double>(best.second) / total};
}

SegmentConfig no_split() {
  SegmentConfig config;
  config.split.max_extent = 10.0;
  return config;
}

TEST(Pipeline, MergesEachCubeIntoOneBoxAndKeepsTheFloorSeparate) {
  const test::Scene scene = two_cubes_on_a_floor();
  const SegmentResult result = segment_cloud(scene.points, no_split());
  const auto boxes = boxes_per_object(scene, result);
  ASSERT_EQ(boxes.size(), 3u);
  // The points along a cube's foot lie within d_th of both the cube and the floor and may go to either box
  // (both hold them); everything else of a cube must be in one box of its own.
  const auto [floor, floor_share] = main_box(boxes, 0);
  EXPECT_GT(floor_share, 0.99);
  for (int cube : {1, 2}) {
    const auto [box, share] = main_box(boxes, cube);
    EXPECT_GT(share, 0.95) << "cube " << cube << " is split over several boxes; " << summary(result.stats);
    EXPECT_NE(box, floor) << "cube " << cube << " merged with the floor";
    // The box is the object's own (true half extents 5 cm, or 6 / 4.5 / 4 cm), not grown toward the floor.
    EXPECT_LT(result.boxes.boxes[box].half_extents.maxCoeff(), cube == 1 ? 0.052 : 0.062) << "cube " << cube;
    EXPECT_GT(result.boxes.boxes[box].half_extents.minCoeff(), cube == 1 ? 0.045 : 0.035) << "cube " << cube;
  }
  EXPECT_NE(main_box(boxes, 1).first, main_box(boxes, 2).first);
  EXPECT_EQ(result.boxes.version, 1u);
  for (std::size_t b = 0; b < result.boxes.boxes.size(); ++b) EXPECT_EQ(result.boxes.boxes[b].id, b + 1);
}

TEST(Pipeline, KeepsABoxStandingOnABoxSeparate) {
  test::Scene scene(Eigen::Vector3f(0.2f, -0.6f, 0.9f));
  scene.add_box({0.0, 0.0, 0.06}, {0.1, 0.08, 0.06}, Eigen::Matrix3d::Identity());    // lower box
  scene.add_box({0.02, 0.0, 0.16}, {0.05, 0.04, 0.04}, Eigen::Matrix3d::Identity());  // standing on it
  scene.add_floor(0.3, {Footprint({-0.1, -0.08}, {0.1, 0.08})});
  // The lower box's top is hidden under the upper box there.
  std::vector<int> keep;
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    const auto& p = scene.points[i];
    const bool hidden =
        scene.object[i] == 1 && p.z > 0.119f && p.x > -0.03f && p.x < 0.07f && std::abs(p.y) < 0.04f;
    if (!hidden) keep.push_back(static_cast<int>(i));
  }
  test::Scene visible(scene.viewpoint());
  for (int i : keep) visible.add(scene.points[i].getVector3fMap(), scene.object[i]);
  const SegmentResult result = segment_cloud(visible.points, no_split());
  const auto boxes = boxes_per_object(visible, result);
  ASSERT_EQ(boxes.size(), 3u);
  const int floor = main_box(boxes, 0).first;
  const auto [lower, lower_share] = main_box(boxes, 1);
  const auto [upper, upper_share] = main_box(boxes, 2);
  EXPECT_GT(lower_share, 0.93) << summary(result.stats);
  EXPECT_GT(upper_share, 0.93) << summary(result.stats);
  EXPECT_NE(lower, upper);
  EXPECT_NE(lower, floor);
  EXPECT_NE(upper, floor);
}

TEST(Pipeline, EveryPointIsInsideABoxOrCountedAsDropped) {
  const test::Scene scene = two_cubes_on_a_floor();
  for (OutlierMode mode : {OutlierMode::kOff, OutlierMode::kTwoSided}) {
    for (BoxKind kind : {BoxKind::kOriented, BoxKind::kAxisAligned}) {
      SegmentConfig config;  // defaults, with the VCCS split of the 60 cm floor
      config.outlier_mode = mode;
      config.box_kind = kind;
      const SegmentResult result = segment_cloud(scene.points, config);
      std::size_t fitted = 0, outside = 0;
      for (const Box& box : result.boxes.boxes) fitted += box.points;
      for (std::size_t i = 0; i < scene.points.size(); ++i) {
        const int b = result.box_of_point[i];
        if (b >= 0) {
          EXPECT_TRUE(result.boxes.boxes[b].contains(scene.points[i].getVector3fMap().cast<double>()));
        }
        bool inside = false;
        for (const Box& box : result.boxes.boxes)
          inside |= box.contains(scene.points[i].getVector3fMap().cast<double>());
        outside += !inside;
      }
      EXPECT_EQ(fitted + result.stats.dropped(), scene.points.size());
      if (mode == OutlierMode::kOff) {
        EXPECT_EQ(result.stats.dropped(), 0u);
        EXPECT_EQ(outside, 0u) << "100 % of the points must be inside boxes";
      } else {
        EXPECT_LE(outside, result.stats.dropped());
      }
      EXPECT_GT(result.stats.split_segments, 0u) << "the floor is longer than max_extent";
    }
  }
}

TEST(Pipeline, ObbVolumeIsAtMostAabbVolumeOnRotatedObjects) {
  test::Scene scene(Eigen::Vector3f(0.0f, -0.8f, 0.8f));
  for (int i = 0; i < 3; ++i) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3 + 0.3 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    scene.add_box({-0.3 + 0.3 * i, 0.0, 0.0}, {0.1, 0.04, 0.03}, R);
  }
  SegmentConfig obb_config = no_split();
  obb_config.outlier_mode = OutlierMode::kOff;
  SegmentConfig aabb_config = obb_config;
  aabb_config.box_kind = BoxKind::kAxisAligned;
  const SegmentResult obb = segment_cloud(scene.points, obb_config);
  const SegmentResult aabb = segment_cloud(scene.points, aabb_config);
  ASSERT_EQ(obb.boxes.boxes.size(), aabb.boxes.boxes.size());
  double obb_volume = 0, aabb_volume = 0;
  for (std::size_t b = 0; b < obb.boxes.boxes.size(); ++b) {
    EXPECT_LE(obb.boxes.boxes[b].volume(), aabb.boxes.boxes[b].volume());
    obb_volume += obb.boxes.boxes[b].volume();
    aabb_volume += aabb.boxes.boxes[b].volume();
  }
  EXPECT_LT(obb_volume, 0.8 * aabb_volume);
}

TEST(Pipeline, ASparseCloudStillConnects) {
  // 3 cm sampling, three times the default d_th of 1 cm: without the gap floor every point would be isolated.
  test::Scene scene(Eigen::Vector3f(0.3f, -1.5f, 1.5f));
  scene.add_box({0.0, 0.0, 0.2}, {0.2, 0.2, 0.2}, Eigen::Matrix3d::Identity(), 0.03);
  scene.add_floor(1.0, {Footprint({-0.2, -0.2}, {0.2, 0.2})}, 0.03);
  SegmentConfig config = no_split();
  config.outlier_mode = OutlierMode::kOff;
  const SegmentResult result = segment_cloud(scene.points, config);
  EXPECT_GE(result.stats.gap, 0.03);
  EXPECT_EQ(result.stats.leftovers.isolated, 0u);
  EXPECT_LE(result.boxes.boxes.size(), 4u) << summary(result.stats);
  config.gap_floor_factor = 0.0;
  const SegmentResult fixed = segment_cloud(scene.points, config);
  EXPECT_EQ(fixed.stats.gap, 0.01);
  EXPECT_GT(fixed.stats.leftovers.isolated, scene.points.size() / 2);
}

TEST(SegmentConfig, TheConfigFileHoldsTheDefaults) {
  const SegmentConfig file = SegmentConfig::load(std::string(CELLMAP_SOURCE_DIR) + "/config/segment.yaml");
  const SegmentConfig defaults;
  EXPECT_EQ(file.k, defaults.k);
  EXPECT_EQ(file.outlier_mode, defaults.outlier_mode);
  EXPECT_EQ(file.outlier_u, defaults.outlier_u);
  EXPECT_EQ(file.region_growing.gap, defaults.region_growing.gap);
  EXPECT_EQ(file.region_growing.max_curvature, defaults.region_growing.max_curvature);
  EXPECT_EQ(file.region_growing.max_angle, defaults.region_growing.max_angle);
  EXPECT_EQ(file.region_growing.min_cluster_size, defaults.region_growing.min_cluster_size);
  EXPECT_EQ(file.gap_floor_factor, defaults.gap_floor_factor);
  EXPECT_EQ(file.leftover_min_points, defaults.leftover_min_points);
  EXPECT_EQ(file.merge, defaults.merge);
  EXPECT_EQ(file.merge_params.gap, defaults.merge_params.gap);
  EXPECT_EQ(file.merge_params.patch_radius, defaults.merge_params.patch_radius);
  EXPECT_EQ(file.merge_params.concavity_tolerance, defaults.merge_params.concavity_tolerance);
  EXPECT_EQ(file.merge_params.min_boundary_points, defaults.merge_params.min_boundary_points);
  EXPECT_EQ(file.merge_params.samples_per_boundary, defaults.merge_params.samples_per_boundary);
  EXPECT_EQ(file.split.max_extent, defaults.split.max_extent);
  EXPECT_EQ(file.split.voxel_resolution, defaults.split.voxel_resolution);
  EXPECT_EQ(file.split.seed_resolution, defaults.split.seed_resolution);
  EXPECT_EQ(file.split_method, defaults.split_method);
  EXPECT_EQ(file.split_min_gain, defaults.split_min_gain);
  EXPECT_EQ(file.join_max_growth, defaults.join_max_growth);
  EXPECT_EQ(file.box_kind, defaults.box_kind);
  EXPECT_EQ(file.voxel, defaults.voxel);
  EXPECT_FALSE(file.workspace.has_value());
  EXPECT_EQ(defaults.merge_params.gap, defaults.region_growing.gap);
}

void expect_config_error(const std::string& yaml, const std::string& key) {
  try {
    (void)SegmentConfig::from_yaml(YamlMap::parse(yaml, "test.yaml"));
    FAIL() << "accepted: " << yaml;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("test.yaml: " + key), std::string::npos) << e.what();
  }
}

TEST(SegmentConfig, UnknownKeysAndOutOfRangeValuesNameTheKey) {
  expect_config_error("region_growing:\n  gapp: 0.01\n", "region_growing.gapp");
  expect_config_error("colour: red\n", "colour");
  expect_config_error("region_growing:\n  gap: -1\n", "region_growing.gap");
  expect_config_error("neighbours:\n  k: 1\n", "neighbours.k");
  expect_config_error("outliers:\n  mode: sideways\n", "outliers.mode");
  expect_config_error("boxes:\n  kind: sphere\n", "boxes.kind");
  expect_config_error("split:\n  voxel_resolution: 0.1\n  seed_resolution: 0.05\n", "split.seed_resolution");
  expect_config_error("workspace:\n  lower: [0, 0]\n  upper: [1, 1, 1]\n", "workspace.lower");
  expect_config_error("merge:\n  enabled: maybe\n", "merge.enabled");
}

TEST(SegmentConfig, WorkspaceCropsAndCountsTheDrop) {
  const SegmentConfig config =
      SegmentConfig::from_yaml(YamlMap::parse("outliers: {mode: 'off'}\nworkspace:\n  lower: [-0.3, -0.3, "
                                              "0.0]\n  upper: [0.0, 0.3, 0.2]\n  envelope: 0.01\n",
                                              "test.yaml"));
  ASSERT_TRUE(config.workspace.has_value());
  const test::Scene scene = two_cubes_on_a_floor();
  const SegmentResult result = segment_cloud(scene.points, config);
  std::size_t outside = 0;
  for (const auto& p : scene.points) outside += p.x > 0.01f + 1e-6f;
  EXPECT_EQ(result.stats.outside_workspace, outside);
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    if (scene.points[i].x > 0.0101f) {
      EXPECT_EQ(result.box_of_point[i], -1);
    }
  }
}

// Found by fuzzing (fuzz_segment_config): yaml-cpp's message for a bad escape quotes the character, a newline
// here, and the refusal took two lines.
TEST(SegmentConfig, FuzzFindingsAreRefusedWithOneLine) {
  const std::string file = test::fuzz_regression("segment_config", "unknown_escape.yaml");
  EXPECT_EQ(test::one_line_error_of([&] {
              (void)SegmentConfig::load(file);
            }).rfind(file + ": YAML syntax error at line 21, column 1: unknown escape character", 0),
            0u);
}

}  // namespace
}  // namespace cellmap
