// SPDX-License-Identifier: Apache-2.0
// The moving cell: a robot that moves all the time along its path while frames are taken, the controller's
// joint samples, pick and place, and a person walking through.
#include "cellmap/sim/motion.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/sim/scene.hpp"
#include "cellmap/sim/simulator.hpp"
#include "support/test_support.hpp"

namespace cellmap::sim {
namespace {

const std::string kScenes = std::string(CELLMAP_SOURCE_DIR) + "/config/scenes";

// The arm cell with its motion replaced: pick the carton off the pallet, carry it (holding still for 5 s),
// put it on the table 1.2 m further and move away; a person walks past the table's far side from t = 1 s to t
// = 4 s.
Scene pick_and_place_scene() {
  std::string text = read_file(kScenes + "/arm_cell.yaml");
  text = text.substr(0, text.find("motion:"));
  text += R"(motion:
  loop: false
  controller_rate: 200
  joint_stamp_delay: 0.02
  waypoints:
    - {time: 0, q: [0.8, 0.4, 0.0, 0.0, 1.1707963267948966, 0.0]}
    - {time: 1, q: [0.5517, 0.94, -0.51, 0.0, 1.1408, 0.0], pick: carton}
    - {time: 3, q: [0.0, 0.4, 0.0, 0.0, 1.1707963267948966, 0.0]}
    - {time: 8, q: [0.0, 0.4, 0.0, 0.0, 1.1707963267948966, 0.0]}
    - {time: 10, q: [-0.3547, 0.9, -0.26, 0.0, 0.9308, 0.0], place: true}
    - {time: 12, q: [-0.8, 0.4, 0.0, 0.0, 1.1707963267948966, 0.0]}
walkers:
  - name: person
    radius: 0.25
    height: 1.75
    path: [{time: 1, at: [-0.4, 2.3]}, {time: 4, at: [3.4, 2.3]}]
)";
  return parse_scene(text, "pick_and_place.yaml", kScenes);
}

TEST(MotionTest, SmoothStepsBetweenWaypointsAndLoops) {
  Motion motion;
  motion.waypoints = {{0.0, Eigen::Vector2d(0, 0), "", false},
                      {2.0, Eigen::Vector2d(1, -2), "", false},
                      {4.0, Eigen::Vector2d(0, 0), "", false}};
  EXPECT_EQ(motion.q_at(2.0), Eigen::Vector2d(1, -2));
  EXPECT_LT((motion.q_at(1.0) - Eigen::Vector2d(0.5, -1)).norm(), 1e-12);           // half way at half time
  EXPECT_LT((motion.q_at(0.5) - Eigen::Vector2d(0.15625, -0.3125)).norm(), 1e-12);  // 3u² − 2u³ at u = 1/4
  EXPECT_LT((motion.q_at(5.0) - motion.q_at(1.0)).norm(), 1e-12);                   // looped
  motion.loop = false;
  EXPECT_EQ(motion.q_at(5.0), Eigen::Vector2d(0, 0));
  const Robot two_axes = Robot::gantry({-5, -5, -5}, {5, 5, 5});
  motion.waypoints[1].time = 5.0;  // after the next one
  EXPECT_THROW(motion.validate(two_axes), Error);
}

TEST(MotionTest, TheArmCellMovesAllTheTime) {
  const Scene scene = load_scene(kScenes + "/arm_cell.yaml");
  ASSERT_TRUE(scene.motion.has_value());
  EXPECT_TRUE(scene.motion->loop);
  SimOptions exact;
  exact.noise = false;
  const Simulator simulator(scene, exact);
  const SimWindow window = simulator.window(0.5, 1.5);
  // 250 Hz for one second; every frame of every sensor at its period (0.2 s): 5 post + 5 wrist.
  EXPECT_EQ(window.joints.size(), 250u);
  EXPECT_EQ(window.frames.size(), 10u);
  for (std::size_t i = 1; i < window.joints.size(); ++i) {
    EXPECT_NEAR(window.joints[i].stamp - window.joints[i - 1].stamp, 0.004, 1e-9);
    EXPECT_FALSE(window.joints[i].q.isApprox(window.joints[i - 1].q));  // never standing still
  }
  for (const SimFrame& f : window.frames) {
    EXPECT_GE(f.frame.stamp, 0.5);
    EXPECT_LT(f.frame.stamp, 1.5);
    EXPECT_TRUE(f.q.isApprox(scene.motion->q_at(f.frame.stamp), 1e-12));
    const int sensor = scene.find_sensor(f.frame.sensor);
    EXPECT_TRUE(f.frame.X_CS.isApprox(scene.sensor_pose(sensor, f.q), 1e-12));
  }
  // A window renders the same frames again (noise keyed by the capture time).
  const SimWindow again = simulator.window(0.5, 1.5);
  EXPECT_EQ(again.frames[3].frame.depth->depth, window.frames[3].frame.depth->depth);
}

TEST(MotionTest, PickAndPlaceCarriesTheBoxAsPartOfTheRobot) {
  const Scene scene = pick_and_place_scene();
  SimOptions exact;
  exact.noise = false;
  const Simulator simulator(scene, exact);
  const Obstacle carton = scene.obstacles[static_cast<std::size_t>(scene.find_obstacle("carton"))];
  auto find = [](const CellState& s, const std::string& name) -> const Obstacle* {
    for (const Obstacle& o : s.obstacles) {
      if (o.name == name) return &o;
    }
    return nullptr;
  };
  const CellState before = simulator.state_at(0.5);
  ASSERT_NE(find(before, "carton"), nullptr);
  EXPECT_FALSE(before.robot.payload.has_value());
  // Carried: no carton obstacle; the payload is the carton where the tool holds it.
  const CellState carried = simulator.state_at(5.0);
  EXPECT_EQ(find(carried, "carton"), nullptr);
  ASSERT_TRUE(carried.robot.payload.has_value());
  const CellState at_pick = simulator.state_at(1.0);
  ASSERT_TRUE(at_pick.robot.payload.has_value());
  EXPECT_TRUE(
      (scene.robot.tool_pose(at_pick.robot.q) * at_pick.robot.payload->X_EB).isApprox(carton.X_CO, 1e-9));
  // Placed: the carton is an obstacle again, where the tool put it.
  const CellState after = simulator.state_at(11.0);
  ASSERT_NE(find(after, "carton"), nullptr);
  EXPECT_FALSE(after.robot.payload.has_value());
  EXPECT_TRUE(
      find(after, "carton")
          ->X_CO.isApprox(scene.robot.tool_pose(scene.motion->waypoints[4].q) * carried.robot.payload->X_EB,
                          1e-9));
  EXPECT_GT((find(after, "carton")->X_CO.translation() - carton.X_CO.translation()).norm(), 0.5);
  // The joint samples carry the payload and are stamped 20 ms late.
  const SimWindow window = simulator.window(4.0, 4.1);
  ASSERT_EQ(window.joints.size(), 20u);
  EXPECT_NEAR(window.joints[0].stamp, 4.02, 1e-9);
  EXPECT_TRUE(window.joints[0].payload.has_value());
  // Frames while carrying see the carton with the robot (robot pixels), none of it as an obstacle.
  std::size_t robot_pixels = 0;
  for (const SimFrame& f : window.frames) {
    for (int hit : f.hit) robot_pixels += hit == RayHit::kRobot;
  }
  EXPECT_GT(robot_pixels, 0u);
}

TEST(MotionTest, APersonWalksThroughAndLeaves) {
  const Scene scene = pick_and_place_scene();
  SimOptions exact;
  exact.noise = false;
  const Simulator simulator(scene, exact);
  EXPECT_EQ(simulator.state_at(0.5).obstacles.size(), scene.obstacles.size());
  const CellState walking = simulator.state_at(2.5);
  ASSERT_EQ(walking.obstacles.size(), scene.obstacles.size() - 1 + 2);  // carton carried, body + head
  const Obstacle& body = walking.obstacles[walking.obstacles.size() - 2];
  EXPECT_EQ(body.name, "person_body");
  EXPECT_LT((body.X_CO.translation().head<2>() - Eigen::Vector2d(1.5, 2.3)).norm(), 1e-9);  // half way
  EXPECT_NEAR(walking.obstacles.back().X_CO.translation().z() + 0.6 * 0.25, 1.75, 1e-9);    // head on top
  // The post camera sees the person while walking and not after.
  auto person_pixels = [&](double t0, double t1) {
    std::size_t n = 0;
    const int post = scene.find_sensor("post");
    for (const SimFrame& f : simulator.window(t0, t1).frames) {
      if (scene.find_sensor(f.frame.sensor) != post) continue;
      const CellState state = simulator.state_at(f.frame.stamp);
      for (int hit : f.hit)
        n += hit >= 0 && state.obstacles[static_cast<std::size_t>(hit)].name.rfind("person", 0) == 0;
    }
    return n;
  };
  EXPECT_GT(person_pixels(2.0, 3.0), 100u);
  EXPECT_EQ(person_pixels(4.2, 5.0), 0u);
}

TEST(MotionTest, MotionAndWalkerKeysAreStrict) {
  std::string text = read_file(kScenes + "/arm_cell.yaml");
  auto error = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    return test::error_of([&] { (void)parse_scene(t, "arm.yaml", kScenes); });
  };
  EXPECT_EQ(error("  loop: true", "  loop: true\n  speed: 2"), "arm.yaml: motion.speed: unknown key");
  EXPECT_NE(error("  loop: true", "  loop: false\n  pick_nothing: 1").find("pick_nothing"),
            std::string::npos);
  EXPECT_EQ(error("  controller_rate: 250", "  controller_rate: 0"),
            "arm.yaml: motion.controller_rate: must be in [1, 10000], got 0");
}

}  // namespace
}  // namespace cellmap::sim
