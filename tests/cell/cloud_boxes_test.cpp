// SPDX-License-Identifier: Apache-2.0
// One cloud through the cell pipeline's stages (the batch tool's path): every point inside a box or counted
// as noise, few boxes on the default cell.
#include <gtest/gtest.h>

#include <algorithm>

#include "cellmap/cell/cloud_boxes.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/simulator.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap {
namespace {

CellPipelineConfig defaults() {
  YamlMap root = YamlMap::load(CELLMAP_SOURCE_DIR "/config/cellmapd.yaml");
  return CellPipelineConfig::from_yaml(root);
}

// The top and the four sides of an axis-aligned box standing on z = 0, a point every 5 mm.
void add_box_surface(Cloud& cloud, const Eigen::Vector3d& centre, const Eigen::Vector3d& half) {
  const double step = 0.005;
  const auto add = [&](double x, double y, double z) {
    cloud.push_back(pcl::PointXYZ(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)));
  };
  const Eigen::Vector3d lo = centre - half, hi = centre + half;
  for (double x = lo.x(); x <= hi.x() + 1e-9; x += step) {
    for (double y = lo.y(); y <= hi.y() + 1e-9; y += step) add(x, y, hi.z());
    for (double z = lo.z(); z <= hi.z() + 1e-9; z += step) add(x, lo.y(), z), add(x, hi.y(), z);
  }
  for (double y = lo.y(); y <= hi.y() + 1e-9; y += step) {
    for (double z = lo.z(); z <= hi.z() + 1e-9; z += step) add(lo.x(), y, z), add(hi.x(), y, z);
  }
}

bool inside_some_box(const BoxSet& set, const pcl::PointXYZ& p) {
  return std::any_of(set.boxes.begin(), set.boxes.end(),
                     [&](const Box& box) { return box.contains(p.getVector3fMap().cast<double>(), 1e-6); });
}

TEST(CloudBoxesTest, TwoSeparateObjectsAreTwoBoxesHoldingTheirPointsAndALonePointIsNoise) {
  Cloud cloud;
  add_box_surface(cloud, {0.5, 0.5, 0.1}, {0.1, 0.15, 0.1});
  add_box_surface(cloud, {1.5, 0.5, 0.15}, {0.2, 0.1, 0.15});
  const std::size_t object_points = cloud.size();
  cloud.push_back(pcl::PointXYZ(1.0f, 1.5f, 0.5f));  // far from both
  cloud.sensor_origin_ = Eigen::Vector4f(1.0f, -0.5f, 1.5f, 0.0f);

  const CloudBoxes result = boxes_of_cloud(cloud, defaults());
  ASSERT_EQ(result.boxes.boxes.size(), 2u);
  for (std::size_t b = 0; b < result.boxes.boxes.size(); ++b) EXPECT_EQ(result.boxes.boxes[b].id, b + 1);
  EXPECT_EQ(result.points, cloud.size());
  EXPECT_EQ(result.noise_voxels, 1u);
  EXPECT_EQ(result.noise_points, 1u);
  EXPECT_EQ(result.outside_boxes, 0u);
  for (std::size_t i = 0; i < object_points; ++i) EXPECT_TRUE(inside_some_box(result.boxes, cloud[i])) << i;
  EXPECT_FALSE(inside_some_box(result.boxes, cloud.back()));
  // Each box is tight: at most a voxel (2 cm) beyond its object on every side.
  std::vector<double> volumes;
  for (const Box& box : result.boxes.boxes) volumes.push_back(box.volume());
  std::sort(volumes.begin(), volumes.end());
  EXPECT_LE(volumes[0], 0.24 * 0.34 * 0.24);
  EXPECT_LE(volumes[1], 0.44 * 0.24 * 0.34);
}

// One Kinect sweep of the default cell as the batch tool gets it. cellmapd's first version of the same cell
// (15 fused sweeps, the same config) is 11 boxes; the batch path must stay within twice that.
TEST(CloudBoxesTest, OneSweepOfTheDefaultCellIsFewBoxesHoldingEveryObstaclePoint) {
  const sim::Scene scene = sim::default_scene();
  const sim::Simulator simulator(scene, sim::SimOptions{true, 2});
  std::vector<Frame> frames;
  for (sim::SimFrame& f : simulator.sweep(scene.find_sensor("kinect"), 0))
    frames.push_back(std::move(f.frame));
  const Sweep sweep = merge_frames(frames);
  Cloud cloud = sweep.merged();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const Scan& scan : sweep.scans) origin += scan.origin_C / static_cast<double>(sweep.scans.size());
  cloud.sensor_origin_ = Eigen::Vector4f(origin.x(), origin.y(), origin.z(), 0.0f);

  const CloudBoxes result = boxes_of_cloud(cloud, defaults());
  EXPECT_GE(result.boxes.boxes.size(), 8u);  // floor, table, pallets, carton, stack, drum, ball, fixture
  EXPECT_LE(result.boxes.boxes.size(), 22u);
  EXPECT_EQ(result.outside_map, 0u);
  EXPECT_EQ(result.outside_boxes, 0u);
  EXPECT_LT(result.noise_points, cloud.size() / 1000);  // measured 75 of 228 354
  std::size_t outside = 0;
  for (const pcl::PointXYZ& p : cloud) outside += inside_some_box(result.boxes, p) ? 0 : 1;
  EXPECT_LE(outside, result.noise_points);  // a noise voxel may lie inside another object's box
}

}  // namespace
}  // namespace cellmap
