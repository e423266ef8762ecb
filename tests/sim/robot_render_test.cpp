// SPDX-License-Identifier: Apache-2.0
// The robot in the simulator: its collision shapes (primitives and meshes through a bounding-volume
// hierarchy) and payload rendered by the ray caster, fixed and wrist sensors, and the arm cell.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/sim/ray_cast.hpp"
#include "cellmap/sim/scene.hpp"
#include "cellmap/sim/simulator.hpp"
#include "support/test_support.hpp"

namespace cellmap::sim {
namespace {

const std::string kArmScene = std::string(CELLMAP_SOURCE_DIR) + "/config/scenes/arm_cell.yaml";

// A closed box surface as 12 triangles, half extents h, centred on its frame.
std::shared_ptr<TriangleMesh> box_mesh(const Eigen::Vector3d& h) {
  auto mesh = std::make_shared<TriangleMesh>();
  for (int i = 0; i < 8; ++i) {
    mesh->vertices.emplace_back((i & 1 ? 1 : -1) * h.x(), (i & 2 ? 1 : -1) * h.y(), (i & 4 ? 1 : -1) * h.z());
  }
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& f : faces) {
    mesh->triangles.emplace_back(f[0], f[1], f[2]);
    mesh->triangles.emplace_back(f[0], f[2], f[3]);
  }
  return mesh;
}

TEST(RobotRenderTest, MeshShapesHitWhereTheAnalyticSolidIs) {
  // The same box on a gantry's ram, once as a mesh and once as a primitive: every ray from outside meets both
  // at the same distance (a box's faces are exactly its 12 triangles).
  const Eigen::Vector3d h(0.3, 0.2, 0.1);
  const Robot gantry = Robot::gantry({0, 0, 0}, {1, 1, 1});
  Eigen::Isometry3d X_LG = Eigen::Isometry3d::Identity();
  X_LG.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X_LG.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  const RobotSolids as_mesh(gantry.with_shapes({{"ram", X_LG, MeshShape{box_mesh(h)}}}));
  const RobotSolids as_box(gantry.with_shapes({{"ram", X_LG, BoxShape{h}}}));
  const JointState state{0.0, Eigen::Vector3d(0.5, 0.25, 0.75), std::nullopt};
  const SceneCaster mesh_caster({}, as_mesh, state), box_caster({}, as_box, state);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Eigen::Vector3d centre = gantry.link_poses(state.q)[3] * X_LG.translation();
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d o = centre + 2.0 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    const Eigen::Vector3d d =
        (centre + 0.4 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) - o).normalized();
    const RayHit m = mesh_caster.cast(o, d, 10.0), b = box_caster.cast(o, d, 10.0);
    ASSERT_EQ(m.obstacle, b.obstacle) << i;
    if (b.obstacle == RayHit::kRobot) {
      ++hits;
      ASSERT_NEAR(m.t, b.t, 1e-9) << i;
    }
  }
  EXPECT_GT(hits, 500);
  // Culling by cones keeps every robot hit too.
  const auto candidates =
      mesh_caster.candidates(centre + Eigen::Vector3d(0, 0, 2), -Eigen::Vector3d::UnitZ(), 0.5);
  EXPECT_EQ(mesh_caster.cast(centre + Eigen::Vector3d(0, 0, 2), -Eigen::Vector3d::UnitZ(), 10, &candidates)
                .obstacle,
            RayHit::kRobot);
}

// Every return of `frame` that hit the robot lies on one of its shapes or the payload: inside a shape's tight
// box grown by `tolerance`.
void expect_robot_points_on_the_robot(const Scene& scene, const SimFrame& f,
                                      const std::optional<Payload>& payload, double tolerance,
                                      int& robot_pixels) {
  const PinholeIntrinsics& k = f.frame.depth->intrinsics;
  std::vector<LinkBox> boxes = scene.robot.shape_boxes();
  std::vector<Eigen::Isometry3d> X_CB;
  const std::vector<Eigen::Isometry3d> X_CL = scene.robot.link_poses(f.q);
  for (std::size_t i = 0; i < boxes.size(); ++i)
    X_CB.push_back(X_CL[scene.robot.shape_links()[i]] * boxes[i].X_LB);
  if (payload) {
    boxes.push_back({"", payload->X_EB, payload->half_extents});
    X_CB.push_back(X_CL.back() * payload->X_EB);
  }
  robot_pixels = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * k.width + u;
      if (f.hit[p] != RayHit::kRobot) continue;
      ++robot_pixels;
      const Eigen::Vector3d p_C =
          f.frame.X_CS * (Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0) * f.exact[p]);
      bool inside = false;
      for (std::size_t i = 0; i < boxes.size() && !inside; ++i) {
        const Eigen::Vector3d p_B = X_CB[i].inverse() * p_C;
        inside = (p_B.cwiseAbs() - boxes[i].half_extents).maxCoeff() <= tolerance;
      }
      ASSERT_TRUE(inside) << "pixel " << u << "," << v << " at " << p_C.transpose();
    }
  }
}

TEST(RobotRenderTest, TheArmIsInViewOfThePostCamera) {
  const Scene scene = load_scene(kArmScene);
  EXPECT_EQ(scene.robot.dof(), 6);
  EXPECT_EQ(scene.robot.shapes().size(), 7u);
  EXPECT_GT(scene.robot.triangle_count(), 400u);
  const int post = scene.find_sensor("post");
  ASSERT_GE(post, 0);
  EXPECT_EQ(scene.sensors[post].mount, Mount::kCell);
  // A fixed camera does not move with the robot.
  EXPECT_TRUE(
      scene.sensor_pose(post, scene.sweep.stops[0]).isApprox(scene.sensor_pose(post, scene.sweep.stops[4])));
  SimOptions exact;
  exact.noise = false;
  const Simulator simulator(scene, exact);
  const SimFrame with = simulator.render(post, scene.sweep.stops[2], 0.0, 0, 0);
  int robot_pixels = 0;
  expect_robot_points_on_the_robot(scene, with, std::nullopt, 1e-6, robot_pixels);
  EXPECT_GT(robot_pixels, 500);
  // Without the robot the same pixels see what is behind it, farther away; every other pixel is unchanged.
  exact.render_robot = false;
  const SimFrame without = Simulator(scene, exact).render(post, scene.sweep.stops[2], 0.0, 0, 0);
  for (std::size_t p = 0; p < with.hit.size(); ++p) {
    if (with.hit[p] == RayHit::kRobot) {
      ASSERT_TRUE(without.exact[p] == 0 || without.exact[p] > with.exact[p]) << p;
    } else {
      ASSERT_EQ(with.hit[p], without.hit[p]) << p;
      ASSERT_EQ(with.exact[p], without.exact[p]) << p;
    }
  }
}

TEST(RobotRenderTest, APayloadRendersWithTheRobot) {
  const Scene scene = load_scene(kArmScene);
  const int post = scene.find_sensor("post");
  SimOptions exact;
  exact.noise = false;
  const Simulator simulator(scene, exact);
  Payload carton;
  carton.X_EB.translation() = Eigen::Vector3d(0, 0, 0.2);  // 20 cm beyond the flange, along the tool's z
  carton.half_extents = Eigen::Vector3d(0.2, 0.15, 0.15);
  const JointState holding{0.0, scene.sweep.stops[2], carton};
  const SimFrame f = simulator.render(post, holding, 0, 0);
  int robot_pixels = 0;
  expect_robot_points_on_the_robot(scene, f, carton, 1e-6, robot_pixels);
  int empty_handed = 0;
  expect_robot_points_on_the_robot(scene, simulator.render(post, scene.sweep.stops[2], 0.0, 0, 0),
                                   std::nullopt, 1e-6, empty_handed);
  EXPECT_GT(robot_pixels, empty_handed + 300);  // the carton is 40 × 30 cm
}

TEST(RobotRenderTest, WristCameraLooksDownOverTheTable) {
  const Scene scene = load_scene(kArmScene);
  const int wrist = scene.find_sensor("wrist");
  ASSERT_GE(wrist, 0);
  SimOptions exact;
  exact.noise = false;
  const Simulator simulator(scene, exact);
  for (const Eigen::VectorXd& q : scene.sweep.stops) {
    const SimFrame f = simulator.render(wrist, q, 0.0, 0, 0);
    const Eigen::Isometry3d X_CS = scene.robot.tool_pose(q) * scene.sensors[wrist].X_ES;
    EXPECT_TRUE(f.frame.X_CS.isApprox(X_CS, 1e-12));
    EXPECT_LT((X_CS.linear() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d(0, 0, -1)).norm(), 1e-9);
    // The table 0.7 m below fills most of the view; of the arm, at most the edge of its base on the pedestal.
    std::size_t obstacles = 0;
    for (int hit : f.hit) obstacles += hit >= 0;
    EXPECT_GT(obstacles, f.hit.size() / 2);
    int robot_pixels = 0;
    expect_robot_points_on_the_robot(scene, f, std::nullopt, 1e-6, robot_pixels);
    EXPECT_LT(robot_pixels, 100);
  }
}

TEST(RobotRenderTest, MountKeysAreStrict) {
  const std::string text = read_file(kArmScene);
  auto broken = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    return test::error_of(
        [&] { (void)parse_scene(t, "arm.yaml", std::string(CELLMAP_SOURCE_DIR) + "/config/scenes"); });
  };
  EXPECT_EQ(broken("mount: cell", "mount: wall"),
            "arm.yaml: sensors[0].mount: must be tool, cell or a pose, got 'wall'");
  EXPECT_EQ(broken("    mount: cell\n    pose:", "    mount: cell\n    where:"),
            "arm.yaml: sensors[0].pose: is required with mount: cell");
}

}  // namespace
}  // namespace cellmap::sim
