// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/scene.hpp"

#include <gtest/gtest.h>

#include "support/test_support.hpp"

#include <cmath>
#include <functional>

#include "cellmap/common/error.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/scene_edit.hpp"

namespace cellmap::sim {
namespace {

using test::error_of;

// A small valid scene; tests replace one line to break it.
const std::string kScene = R"(cell: {min: [0, 0, 0], max: [4, 3, 3]}
obstacles:
  - {name: table, box: {half_extents: [1.5, 1.0, 0.05]}, center: [2, 1.5, 0.7]}
  - {name: drum, cylinder: {radius: 0.2, length: 0.4}, center: [1.5, 1.5, 0.95]}
  - {name: ball, sphere: {radius: 0.1}, center: [2.5, 1.5, 0.85]}
robot:
  gantry: {lower: [0, 0, -0.5], upper: [3, 2, 0], tool_at_zero: {position: [0.5, 0.5, 2.5], rotation: [0, 1, 0, 0]}}
sensors:
  - {name: cam, model: kinect_v2, mount: {position: [0, 0, 0.05]}, seed: 4}
sweep:
  period: 0.5
  line: {from: [0.5, 1.0, 0], to: [2.5, 1.0, 0], count: 3}
)";

std::string replaced(const std::string& from, const std::string& to) {
  std::string text = kScene;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

std::string parse_error(const std::string& text) {
  return error_of([&] { (void)parse_scene(text, "scene.yaml"); });
}

TEST(SceneTest, ParsesShapesPosesRobotSensorsAndPlan) {
  const Scene scene = parse_scene(kScene, "scene.yaml");
  ASSERT_EQ(scene.obstacles.size(), 3u);
  EXPECT_EQ(scene.obstacles[1].name, "drum");
  EXPECT_DOUBLE_EQ(std::get<CylinderShape>(scene.obstacles[1].shape).half_length, 0.2);
  ASSERT_EQ(scene.sensors.size(), 1u);
  EXPECT_EQ(scene.sensors[0].seed, 4u);
  EXPECT_EQ(scene.sensors[0].intrinsics.width, 512);  // the model's native mode when none is given
  ASSERT_EQ(scene.sweep.stops.size(), 3u);
  EXPECT_TRUE(scene.sweep.stops[1].isApprox(Eigen::Vector3d(1.5, 1.0, 0)));
  // Tool at q: (0.5 + qx, 0.5 + qy, 2.5 + qz) looking down; the camera 5 cm along the tool's z (down).
  const Eigen::Isometry3d X_CS = scene.sensor_pose(0, scene.sweep.stops[1]);
  EXPECT_TRUE(X_CS.translation().isApprox(Eigen::Vector3d(2.0, 1.5, 2.45), 1e-12));
  EXPECT_TRUE((X_CS.linear() * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));
  EXPECT_EQ(scene.find_sensor("kinect_v2"), 0);
  EXPECT_EQ(scene.find_sensor("cam"), 0);
  EXPECT_EQ(scene.find_sensor("os32c"), -1);
}

TEST(SceneTest, GridPlanIsSerpentine) {
  const Scene scene =
      parse_scene(replaced("line: {from: [0.5, 1.0, 0], to: [2.5, 1.0, 0], count: 3}",
                           "grid: {from: [0.5, 0.5, 0], to: [2.5, 1.5, 0], counts: [3, 2, 1]}"),
                  "scene.yaml");
  const std::vector<Eigen::Vector3d> expected = {{0.5, 0.5, 0}, {1.5, 0.5, 0}, {2.5, 0.5, 0},
                                                 {2.5, 1.5, 0}, {1.5, 1.5, 0}, {0.5, 1.5, 0}};
  ASSERT_EQ(scene.sweep.stops.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k)
    EXPECT_TRUE(scene.sweep.stops[k].isApprox(expected[k])) << k;
}

TEST(SceneTest, BadFilesNameTheKey) {
  EXPECT_EQ(parse_error(replaced("center: [1.5, 1.5, 0.95]}", "center: [1.5, 1.5, 0.95], colour: red}")),
            "scene.yaml: obstacles[1].colour: unknown key");
  EXPECT_EQ(parse_error(replaced("half_extents: [1.5, 1.0, 0.05]", "half_extents: [1.5, -1.0, 0.05]")),
            "scene.yaml: obstacles[0].box.half_extents: must be positive, got [1.5, -1, 0.05]");
  EXPECT_EQ(parse_error(replaced("radius: 0.1", "radius: -0.1")),
            "scene.yaml: obstacles[2].sphere.radius: must be positive, got -0.1");
  EXPECT_EQ(parse_error(replaced("length: 0.4", "length: 0")),
            "scene.yaml: obstacles[1].cylinder.length: must be positive, got 0");
  EXPECT_EQ(
      parse_error(replaced("model: kinect_v2", "model: kinect_v3")),
      "scene.yaml: sensors[0].model: unknown sensor model 'kinect_v3' (known: kinect_v2, realsense_d435, "
      "os32c)");
  // A quoted value with line breaks (a folded YAML string, found by fuzz_scene) stays on one line.
  EXPECT_EQ(
      parse_error(replaced("model: kinect_v2", "model: \"kinect\\nv3\"")),
      "scene.yaml: sensors[0].model: unknown sensor model 'kinect?v3' (known: kinect_v2, realsense_d435, "
      "os32c)");
  EXPECT_EQ(parse_error(replaced("period: 0.5", "period: 0.5\n  speed: 2")),
            "scene.yaml: sweep.speed: unknown key");
  EXPECT_EQ(parse_error(replaced("name: ball", "name: drum")),
            "scene.yaml: obstacles[2] 'drum': name used twice");
  EXPECT_EQ(
      parse_error(replaced("sphere: {radius: 0.1}", "sphere: {radius: 0.1}, box: {half_extents: [1, 1, 1]}")),
      "scene.yaml: obstacles[2].box: exactly one of box, cylinder, sphere is required");
  EXPECT_EQ(parse_error(replaced("center: [2.5, 1.5, 0.85]", "center: [2.5, 1.5]")),
            "scene.yaml: obstacles[2].center: must have 3 numbers, got 2");
  EXPECT_EQ(parse_error(replaced("rotation: [0, 1, 0, 0]", "rotation: [0, 2, 0, 0]"))
                .rfind("scene.yaml: robot.gantry.tool_at_zero.rotation: must be a unit quaternion", 0),
            0u);
  EXPECT_EQ(parse_error(replaced("count: 3", "count: 0")),
            "scene.yaml: sweep.line.count: must be an integer in [1, 100000], got 0");
}

TEST(SceneTest, SensorOutsideTheCellAndStopsOutsideTheLimitsAreNamed) {
  // The camera 3 m above the flange: 5.45 m high at every stop, the cell ends at 3 m.
  EXPECT_EQ(
      parse_error(replaced("mount: {position: [0, 0, 0.05]}", "mount: {position: [0, 0, -3]}")),
      "scene.yaml: sensors[0].mount: sensor 'cam' is outside the cell at sweep stop 0 (sensor at [1, 1.5, "
      "5.5], cell [0, 0, 0] to [4, 3, 3])");
  EXPECT_EQ(parse_error(replaced("to: [2.5, 1.0, 0]", "to: [3.5, 1.0, 0]"))
                .rfind("scene.yaml: sweep: stop 2 q = [3.5, 1, 0] is outside the robot's joint limits", 0),
            0u);
  EXPECT_EQ(parse_error(replaced("from: [0.5, 1.0, 0]", "from: [0.5, 1.0]")),
            "scene.yaml: sweep.line.from: must have 3 numbers, got 2");
}

TEST(SceneTest, DefaultSceneIsTheRealisticCell) {
  const Scene scene = default_scene();
  EXPECT_GE(scene.obstacles.size(), 15u);
  for (const char* name : {"table_top", "pallet_a", "pallet_b", "fixture_plate", "stack_1", "stack_3"}) {
    EXPECT_GE(scene.find_obstacle(name), 0) << name;
  }
  // The table is 3 m × 2 m.
  const auto& table =
      std::get<BoxShape>(scene.obstacles[static_cast<std::size_t>(scene.find_obstacle("table_top"))].shape);
  EXPECT_DOUBLE_EQ(2 * table.half_extents.x(), 3.0);
  EXPECT_DOUBLE_EQ(2 * table.half_extents.y(), 2.0);
  EXPECT_GE(scene.find_sensor("kinect_v2"), 0);
  EXPECT_GE(scene.find_sensor("realsense_d435"), 0);
  EXPECT_GE(scene.find_sensor("os32c"), 0);
  // Stereo depth is smoothed, time of flight is not.
  EXPECT_EQ(default_intrinsics(SensorModel::kRealsenseD435).smoothing_radius, kStereoSmoothingRadius);
  EXPECT_EQ(default_intrinsics(SensorModel::kKinectV2).smoothing_radius, 0);
  EXPECT_EQ(without_depth_filter(scene)
                .sensors[static_cast<std::size_t>(scene.find_sensor("realsense_d435"))]
                .intrinsics.smoothing_radius,
            0);
}

TEST(ObstacleTest, SignedDistanceVolumeAndSurfaceSamples) {
  Obstacle box{"b", BoxShape{Eigen::Vector3d(1, 2, 3)}, Eigen::Isometry3d::Identity()};
  box.X_CO.translation() = Eigen::Vector3d(10, 0, 0);
  EXPECT_DOUBLE_EQ(box.signed_distance({13, 0, 0}), 2.0);
  EXPECT_DOUBLE_EQ(box.signed_distance({10, 0, 0}), -1.0);
  EXPECT_DOUBLE_EQ(box.signed_distance({12, 3, 0}), std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(box.volume(), 48.0);
  EXPECT_DOUBLE_EQ(box.surface_area(), 2 * (2 * 4 + 4 * 6 + 2 * 6));
  const Obstacle cylinder{"c", CylinderShape{1.0, 2.0}, Eigen::Isometry3d::Identity()};
  EXPECT_DOUBLE_EQ(cylinder.signed_distance({0, 3, 0}), 2.0);
  EXPECT_DOUBLE_EQ(cylinder.signed_distance({0, 0, 5}), 3.0);
  EXPECT_DOUBLE_EQ(cylinder.signed_distance({0, 0, 1.5}), -0.5);
  EXPECT_NEAR(cylinder.volume(), M_PI * 4, 1e-12);
  const Obstacle sphere{"s", SphereShape{2.0}, Eigen::Isometry3d::Identity()};
  EXPECT_DOUBLE_EQ(sphere.signed_distance({0, 0, 3}), 1.0);
  for (const Obstacle& o : {box, cylinder, sphere}) {
    const std::vector<Eigen::Vector3d> samples = o.sample_surface(0.05);
    EXPECT_GT(samples.size(), o.surface_area() / (0.05 * 0.05) * 0.5);
    for (const Eigen::Vector3d& p : samples) EXPECT_NEAR(o.signed_distance(p), 0.0, 1e-9) << o.name;
  }
}

TEST(SceneEditTest, AddRemoveMoveByName) {
  Scene scene = parse_scene(kScene, "scene.yaml");
  using transport::SceneEdit;
  SceneEdit crate = SceneEdit::add_box("", {1, 1, 0.85}, {0.1, 0.1, 0.1});
  EXPECT_EQ(apply(scene, crate), "added_1");
  EXPECT_EQ(apply(scene, crate), "added_2");
  EXPECT_EQ(scene.obstacles.size(), 5u);
  EXPECT_EQ(apply(scene, SceneEdit::move("drum", {1.0, 2.0, 0.95})), "drum");
  EXPECT_TRUE(scene.obstacles[1].X_CO.translation().isApprox(Eigen::Vector3d(1.0, 2.0, 0.95)));
  EXPECT_EQ(apply(scene, SceneEdit::remove("ball")), "ball");
  EXPECT_EQ(scene.find_obstacle("ball"), -1);
  EXPECT_EQ(scene.obstacles.size(), 4u);

  const Scene before = scene;
  EXPECT_EQ(error_of([&] { (void)apply(scene, SceneEdit::remove("ball")); }),
            "scene edit: remove: no obstacle named 'ball'");
  EXPECT_EQ(error_of([&] {
              (void)apply(scene, SceneEdit::move("nothing", {0, 0, 0}));
            }),
            "scene edit: move: no obstacle named 'nothing'");
  crate.name = "table";
  EXPECT_EQ(error_of([&] { (void)apply(scene, crate); }),
            "scene edit: add: an obstacle named 'table' already exists");
  crate.name = "flat";
  crate.half_extents = Eigen::Vector3d(0.1, 0.0, 0.1);
  EXPECT_NE(error_of([&] { (void)apply(scene, crate); }), "");
  EXPECT_NE(error_of([&] { (void)apply(scene, SceneEdit::move("drum", {NAN, 0, 0})); }), "");
  EXPECT_EQ(scene.obstacles.size(), before.obstacles.size());  // failed edits change nothing
  EXPECT_TRUE(scene.obstacles[1].X_CO.isApprox(before.obstacles[1].X_CO));
}

TEST(SceneEditTest, AFloodOfAddedBoxesStopsAtTheMostASceneHolds) {
  Scene scene = parse_scene(kScene, "scene.yaml");
  const auto crate = transport::SceneEdit::add_box("", {1, 1, 0.85}, {0.01, 0.01, 0.01});
  while (scene.obstacles.size() < kMaxSceneObstacles) (void)apply(scene, crate);
  EXPECT_EQ(error_of([&] { (void)apply(scene, crate); }),
            "scene edit: add: the scene holds 256 obstacles, the most a simulated cell takes");
  EXPECT_EQ(apply(scene, transport::SceneEdit::remove("added_1")), "added_1");
  EXPECT_EQ(apply(scene, crate), "added_1");  // room again
}

}  // namespace
}  // namespace cellmap::sim

namespace cellmap::sim {
namespace {

TEST(SceneTest, UrdfArmSceneLoadsWithItsPathRelativeToTheFile) {
  const Scene scene = load_scene(std::string(CELLMAP_SOURCE_DIR) + "/config/scenes/scara_cell.yaml");
  EXPECT_EQ(scene.robot.dof(), 3);
  EXPECT_EQ(scene.robot.joint_names(), (std::vector<std::string>{"shoulder", "elbow", "lift"}));
  ASSERT_EQ(scene.sweep.stops.size(), 5u);
  // Shoulder 0, elbow 0.8: flange at base + 0.6 x + 0.5 (cos 0.8, sin 0.8), looking down; camera 5 cm below.
  const Eigen::Isometry3d X_CS = scene.sensor_pose(0, scene.sweep.stops[2]);
  const Eigen::Vector3d expected(1.5 + 0.6 + 0.5 * std::cos(0.8), 1.0 + 0.5 * std::sin(0.8), 2.35);
  EXPECT_TRUE(X_CS.translation().isApprox(expected, 1e-12));
  EXPECT_TRUE((X_CS.linear() * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));
  EXPECT_EQ(error_of([] { (void)load_scene("/nonexistent/scene.yaml"); }).find("/nonexistent/scene.yaml"),
            0u);
}

}  // namespace
}  // namespace cellmap::sim

namespace cellmap::sim {
namespace {

TEST(SceneTest, GantryPartsDefaultToAFittingGantryAndCanBeGiven) {
  const Scene fitted = parse_scene(kScene, "s.yaml");
  ASSERT_EQ(fitted.robot.shapes().size(), 3u);
  const GantryParts parts =
      GantryParts::fitting({0, 0, -0.5}, {3, 2, 0}, fitted.robot.tool_pose(Eigen::Vector3d::Zero()));
  EXPECT_LT((fitted.robot.shape_poses(Eigen::Vector3d::Zero())[2].translation() - parts.ram.center).norm(),
            1e-12);
  const Scene given =
      parse_scene(replaced("rotation: [0, 1, 0, 0]}}",
                           "rotation: [0, 1, 0, 0]}, ram: {center: [0.5, 0.5, 3], half_extents: "
                           "[0.05, 0.05, 0.5]}}"),
                  "s.yaml");
  EXPECT_LT(
      (given.robot.shape_poses(Eigen::Vector3d(1, 1, 0))[2].translation() - Eigen::Vector3d(1.5, 1.5, 3))
          .norm(),
      1e-12);
  EXPECT_EQ(std::get<BoxShape>(given.robot.shapes()[2].geometry).half_extents,
            Eigen::Vector3d(0.05, 0.05, 0.5));
  EXPECT_EQ(error_of([] {
              (void)parse_scene(replaced("rotation: [0, 1, 0, 0]}}",
                                         "rotation: [0, 1, 0, 0]}, ram: {center: [0, 0, "
                                         "0], half_extents: [0, 1, 1]}}"),
                                "s.yaml");
            }),
            "s.yaml: robot.gantry.ram.half_extents: must be positive, got [0, 1, 1]");
}

}  // namespace
}  // namespace cellmap::sim
