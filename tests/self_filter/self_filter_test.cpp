// SPDX-License-Identifier: Apache-2.0
// The self filter against known answers: a box robot in front of a camera (which points go, which stay, where
// the clear-only rays end, what fusion makes of it), the padding's documented growth, a line scanner, the
// mesh arms of the simulated cell, and bad input.
#include "cellmap/self_filter/self_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "cellmap/common/error.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/sim/noise.hpp"
#include "cellmap/sim/scene.hpp"
#include "cellmap/sim/simulator.hpp"
#include "cellmap/urdf/urdf_model.hpp"
#include "support/shared_data.hpp"

namespace cellmap {
namespace {

const std::string kArmScene = std::string(CELLMAP_SOURCE_DIR) + "/config/scenes/arm_cell.yaml";
const std::filesystem::path kIrb2400 =
    test::shared_data_dir() / "robots" / "abb_irb2400_support" / "urdf" / "irb2400.urdf";

struct Box {
  Eigen::Vector3d centre;
  Eigen::Vector3d half;
};

// Distance along the unit ray (o, d) to where it enters `box`, or infinity (slab test).
double entry(const Box& box, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double t_near = 0.0, t_far = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    const double lo = box.centre[i] - box.half[i], hi = box.centre[i] + box.half[i];
    if (std::abs(d[i]) < 1e-15) {
      if (o[i] < lo || o[i] > hi) return std::numeric_limits<double>::infinity();
      continue;
    }
    double t0 = (lo - o[i]) / d[i], t1 = (hi - o[i]) / d[i];
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
  }
  return t_near <= t_far ? t_near : std::numeric_limits<double>::infinity();
}

// The test cell, in the camera's frame (the camera at the cell origin looking along +z, y down): a wall
// 3 m away, the robot's box 1.5 m away, slightly off the optical axis so no pixel centre grazes an edge, and
// an obstacle beside it.
const Box kRobotBox{{0.031, -0.017, 1.5}, {0.2, 0.15, 0.2}};
const Box kWall{{0.0, 0.0, 3.05}, {3.0, 3.0, 0.05}};
const Box kBeside{{0.75, 0.0, 1.55}, {0.15, 0.15, 0.15}};

PinholeIntrinsics camera(int width = 160, int height = 120) {
  PinholeIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 140.0 * width / 160.0;
  k.cx = (width - 1) / 2.0;
  k.cy = (height - 1) / 2.0;
  k.max_range = 10.0;
  return k;
}

// A camera frame of `boxes` (exact depths, 1 mm units) taken from X_CS; `label[i]` is the box each valid
// point (in points_S order) lies on.
struct Rendered {
  Frame frame;
  std::vector<int> label;
};
Rendered render(const std::vector<Box>& boxes, const Eigen::Isometry3d& X_CS, const PinholeIntrinsics& k) {
  Rendered out;
  out.frame.X_CS = X_CS;
  out.frame.depth = DepthImage{k, std::vector<std::uint16_t>(std::size_t(k.width * k.height), 0)};
  std::vector<int> pixel_label(out.frame.depth->depth.size(), -1);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d ray_S((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const Eigen::Vector3d d_C = X_CS.linear() * ray_S.normalized();
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t b = 0; b < boxes.size(); ++b) {
        const double t = entry(boxes[b], X_CS.translation(), d_C);
        if (t < best) {
          best = t;
          pixel_label[std::size_t(v * k.width + u)] = int(b);
        }
      }
      if (std::isfinite(best)) {
        out.frame.depth->depth[std::size_t(v * k.width + u)] =
            std::uint16_t(std::lround(best / ray_S.norm() * 1000));
      }
    }
  }
  const Cloud organized = depth_to_points(*out.frame.depth, true);
  for (std::size_t i = 0; i < organized.size(); ++i) {
    if (!std::isfinite(organized[i].z)) continue;
    out.frame.points_S.push_back(organized[i]);
    out.label.push_back(pixel_label[i]);
  }
  return out;
}

// A robot of one link, "base", at the cell origin, with `box` as its collision shape.
Robot box_robot(const Box& box) {
  Eigen::Isometry3d X_LG = Eigen::Isometry3d::Identity();
  X_LG.translation() = box.centre;
  return Robot::serial("base", {}).with_shapes({LinkShape{"base", X_LG, BoxShape{box.half}}});
}
RobotAt at_rest(const Robot& robot) {
  return RobotAt{robot.link_poses(Eigen::VectorXd(robot.dof())), std::nullopt};
}

SelfFilterConfig padding(double scale, double offset) {
  SelfFilterConfig config;
  config.padding_scale = scale;
  config.padding = offset;
  return config;
}

Box padded(const Box& box, const SelfFilterConfig& config) {
  return Box{box.centre, box.half * config.padding_scale + Eigen::Vector3d::Constant(config.padding)};
}

Eigen::Vector3d vec(const pcl::PointXYZ& p) {
  return Eigen::Vector3d(p.x, p.y, p.z);
}

TEST(SelfFilterTest, BoxRobotInFrontOfACameraIsCutOutAndItsRaysStopAtItsPaddedFace) {
  const Rendered shot = render({kWall, kRobotBox, kBeside}, Eigen::Isometry3d::Identity(), camera());
  const SelfFilterConfig config;  // the defaults: 4 cm
  const SelfFilter filter(box_robot(kRobotBox), config);
  const SelfFilterResult result = filter.filter(shot.frame, at_rest(box_robot(kRobotBox)));
  EXPECT_EQ(result.kept + result.removed, shot.frame.points_S.size());
  EXPECT_EQ(result.scan.origin_C, Eigen::Vector3d::Zero());
  // Every point on the robot is removed; every point on the obstacle beside it stays, untouched; of the wall,
  // exactly the points whose line of sight passes through the padded box (its silhouette's 4 cm rim) go.
  const Box grown = padded(kRobotBox, config);
  std::size_t robot = 0, beside = 0, rim = 0;
  for (std::size_t i = 0; i < shot.label.size(); ++i) {
    robot += shot.label[i] == 1;
    beside += shot.label[i] == 2;
    const Eigen::Vector3d p = vec(shot.frame.points_S[i]);
    rim += shot.label[i] == 0 && std::isfinite(entry(grown, Eigen::Vector3d::Zero(), p.normalized()));
  }
  ASSERT_GT(robot, 500u);
  ASSERT_GT(beside, 300u);
  ASSERT_GT(rim, 100u);
  EXPECT_EQ(result.removed, robot + rim);
  std::size_t kept_beside = 0;
  for (const pcl::PointXYZ& p : result.scan.points_C) {
    const Eigen::Vector3d d = (vec(p) - kRobotBox.centre).cwiseAbs() - kRobotBox.half;
    ASSERT_GT(d.maxCoeff(), 0.02) << "a point on the robot survived: " << vec(p).transpose();
    kept_beside += ((vec(p) - kBeside.centre).cwiseAbs() - kBeside.half).maxCoeff() < 1e-3;
  }
  EXPECT_EQ(kept_beside, beside);
  // Each clear-only ray ends where its line of sight enters the padded box (1 mm: float depths).
  ASSERT_EQ(result.scan.clear_C.size(), result.removed);
  for (const pcl::PointXYZ& end : result.scan.clear_C) {
    const Eigen::Vector3d e = vec(end);
    ASSERT_NEAR(e.norm(), entry(grown, Eigen::Vector3d::Zero(), e.normalized()), 1e-3) << e.transpose();
  }
}

TEST(SelfFilterTest, PaddingGrowsTheRemovedRegionAsDocumented) {
  const Rendered shot = render({kWall, kRobotBox}, Eigen::Isometry3d::Identity(), camera());
  std::size_t previous = 0;
  for (const SelfFilterConfig& config : {padding(1.0, 0.005), padding(1.0, 0.04), padding(1.25, 0.0),
                                         padding(1.25, 0.04), padding(1.0, 0.2)}) {
    const SelfFilterResult result =
        SelfFilter(box_robot(kRobotBox), config).filter(shot.frame, at_rest(box_robot(kRobotBox)));
    // The removed points are exactly those whose line of sight meets the box scaled about its centre, then
    // grown by the offset (at least 5 mm: with none, half the robot's depths, rounded to 1 mm, would lie in
    // front of it).
    const Box grown = padded(kRobotBox, config);
    std::size_t expected = 0;
    for (const pcl::PointXYZ& p : shot.frame.points_S) {
      expected += std::isfinite(entry(grown, Eigen::Vector3d::Zero(), vec(p).normalized()));
    }
    EXPECT_EQ(result.removed, expected) << config.padding_scale << " " << config.padding;
    EXPECT_GT(result.removed, previous);
    previous = result.removed;
  }
}

TEST(SelfFilterTest, FusionClearsInFrontOfTheRobotAndLeavesWhatItHidesUnchanged) {
  OccupancyConfig occupancy;
  occupancy.resolution = 0.04;  // the robot's front face (z = 1.3 m) lies inside a voxel, not on a border
  const Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  const Robot robot = box_robot(kRobotBox);
  // First the cell without the robot (the wall is seen, everything in front of it cleared once), then 12
  // sweeps with the robot standing in front of the wall.
  auto map_after = [&](const SelfFilterConfig& config, bool clear_rays, int sweeps) {
    auto map = std::make_unique<OccupancyMap>(occupancy);
    Sweep empty_cell;
    empty_cell.scans.push_back(to_scan(render({kWall}, X_CS, camera()).frame));
    map->integrate(empty_cell);
    const SelfFilter filter(robot, config);
    const Frame with_robot = render({kWall, kRobotBox}, X_CS, camera()).frame;
    for (int i = 0; i < sweeps; ++i) {
      Sweep sweep;
      sweep.scans.push_back(filter.filter(with_robot, at_rest(robot)).scan);
      if (!clear_rays) sweep.scans.back().clear_C.clear();
      map->integrate(sweep);
    }
    return map;
  };
  const auto first = map_after(SelfFilterConfig{}, true, 0);
  const auto filtered = map_after(SelfFilterConfig{}, true, 12);
  auto log_odds = [](const OccupancyMap& map, const Eigen::Vector3d& p) {
    const octomap::OcTreeNode* node = map.tree().search(p.x(), p.y(), p.z());
    return node == nullptr ? std::nanf("") : node->getLogOdds();
  };
  const Eigen::Vector3d behind(0.03, -0.02, 3.01), in_front(0.03, -0.02, 1.0), on_robot(0.03, -0.02, 1.3);
  // The wall behind the robot and the robot's own voxels keep exactly the evidence of the first sweep.
  EXPECT_EQ(filtered->state(behind), VoxelState::occupied);
  EXPECT_EQ(log_odds(*filtered, behind), log_odds(*first, behind));
  EXPECT_EQ(log_odds(*filtered, on_robot), log_odds(*first, on_robot));
  for (const octomap::OcTreeKey& k : filtered->occupied_keys()) {
    const Eigen::Vector3d d = (filtered->centre(k) - kRobotBox.centre).cwiseAbs() - kRobotBox.half;
    ASSERT_GT(d.maxCoeff(), 0.0) << "robot voxel occupied at " << filtered->centre(k).transpose();
  }
  // In front of the robot the clear-only rays (and only they) cleared on: down to the lower clamp.
  EXPECT_EQ(filtered->state(in_front), VoxelState::free);
  EXPECT_LT(log_odds(*filtered, in_front), log_odds(*first, in_front));
  EXPECT_FLOAT_EQ(log_odds(*filtered, in_front),
                  float(std::log(occupancy.clamp_min / (1 - occupancy.clamp_min))));
  EXPECT_EQ(log_odds(*map_after(SelfFilterConfig{}, false, 12), in_front), log_odds(*first, in_front));
  // Without the filter the robot is an obstacle.
  SelfFilterConfig off;
  off.enabled = false;
  EXPECT_EQ(map_after(off, true, 12)->state(on_robot), VoxelState::occupied);
  EXPECT_EQ(filtered->state(on_robot), VoxelState::free);
}

TEST(SelfFilterTest, LineScannerPointsAreTestedAgainstThePaddedShapes) {
  // A scanner frame has no depth image: 181 beams in the x-z plane of S, over the robot and the wall.
  const Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  Frame frame;
  frame.X_CS = X_CS;
  std::size_t robot_beams = 0;
  const SelfFilterConfig config;
  const Box grown = padded(kRobotBox, config);
  std::size_t padded_beams = 0;
  for (int i = -90; i <= 90; ++i) {
    const double a = i * 0.005;
    const Eigen::Vector3d d(std::sin(a), -0.017, std::cos(a));
    const Eigen::Vector3d u = d.normalized();
    const double t_robot = entry(kRobotBox, Eigen::Vector3d::Zero(), u),
                 t_wall = entry(kWall, Eigen::Vector3d::Zero(), u);
    const double t = std::min(t_robot, t_wall);
    robot_beams += t_robot < t_wall;
    padded_beams += std::isfinite(entry(grown, Eigen::Vector3d::Zero(), u));
    const Eigen::Vector3d p = u * t;
    frame.points_S.push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
  }
  const Robot robot = box_robot(kRobotBox);
  const SelfFilterResult result = SelfFilter(robot, config).filter(frame, at_rest(robot));
  ASSERT_GT(robot_beams, 20u);
  EXPECT_GT(padded_beams, robot_beams);
  EXPECT_EQ(result.removed, padded_beams);
  for (const pcl::PointXYZ& end : result.scan.clear_C) {
    ASSERT_NEAR(vec(end).norm(), entry(grown, Eigen::Vector3d::Zero(), vec(end).normalized()), 1e-4);
  }
}

// A simulated frame (noise on) filtered in two parts: the points of pixels that see the robot, and the rest.
struct Survivors {
  std::size_t robot_points = 0;
  /// Robot points kept although their depth is within the sensor's noise bound of the robot's surface.
  std::size_t survivors = 0;
  /// Robot pixels whose depth the sensor mixed with a nearer surface beside the robot (flying pixels, stereo
  /// smear at depth edges), more than the noise bound in front of the robot: kept, as nothing tells them
  /// from a point in front of the robot.
  std::size_t mixed_kept = 0;
  std::size_t other_points = 0;
  std::size_t removed_elsewhere = 0;  ///< of the other points, those within the padding's rim
};
Survivors filter_sim_frame(const sim::Scene& scene, int sensor, const JointState& state,
                           const SelfFilterConfig& config) {
  const sim::Simulator simulator(scene);
  const sim::SimFrame shot = simulator.render(sensor, state, 3, 0);
  const sim::SensorSpec& spec = scene.sensors[std::size_t(sensor)];
  const sim::NoiseModel noise = sim::noise_model(spec.model, spec.intrinsics);
  const Cloud organized = depth_to_points(*shot.frame.depth, true);
  Frame on_robot = shot.frame, mixed = shot.frame, others = shot.frame;
  for (Frame* f : {&on_robot, &mixed, &others}) f->points_S.clear();
  for (std::size_t i = 0; i < organized.size(); ++i) {
    if (!std::isfinite(organized[i].z)) continue;
    Frame& part = shot.hit[i] != sim::RayHit::kRobot                                    ? others
                  : organized[i].z >= shot.exact[i] - noise.bound(shot.exact[i]) - 5e-4 ? on_robot
                                                                                        : mixed;
    part.points_S.push_back(organized[i]);
  }
  const SelfFilter filter(scene.robot, config);
  const RobotAt robot{scene.robot.link_poses(state.q), state.payload};
  Survivors s;
  s.robot_points = on_robot.points_S.size() + mixed.points_S.size();
  s.survivors = filter.filter(on_robot, robot).kept;
  s.mixed_kept = filter.filter(mixed, robot).kept;
  s.other_points = others.points_S.size();
  s.removed_elsewhere = filter.filter(others, robot).removed;
  std::printf("robot points %zu, survivors %zu, mixed depths kept %zu; others %zu, removed %zu\n",
              s.robot_points, s.survivors, s.mixed_kept, s.other_points, s.removed_elsewhere);
  return s;
}

TEST(SelfFilterTest, TheMeshArmOfTheArmCellRemovesItselfFromThePostCamera) {
  const sim::Scene scene = sim::load_scene(kArmScene);
  const int post = scene.find_sensor("post");
  Payload carton;
  carton.X_EB.translation() = Eigen::Vector3d(0, 0, 0.2);
  carton.half_extents = Eigen::Vector3d(0.2, 0.15, 0.15);
  for (const JointState& state :
       {JointState{0.0, scene.sweep.stops[2], std::nullopt}, JointState{0.0, scene.sweep.stops[0], carton}}) {
    const Survivors s = filter_sim_frame(scene, post, state, SelfFilterConfig{});
    ASSERT_GT(s.robot_points, 800u);
    // Kinect v2 noise at 3 m stays well inside the 4 cm padding: no survivor. Flying pixels at the arm's
    // edges keep a few mixed depths (measured: 5 and 8 of ~2 500).
    EXPECT_EQ(s.survivors, 0u) << s.robot_points;
    EXPECT_LE(s.mixed_kept, s.robot_points / 100);
    // The rim the padding removes around the arm is a small share of the rest of the view.
    EXPECT_LT(s.removed_elsewhere, s.other_points / 20);
  }
}

TEST(SelfFilterTest, TheWristCameraKeepsTheTable) {
  // The wrist camera sits 8 cm beside the flange: the arm's tool-side links must not hide the table.
  const sim::Scene scene = sim::load_scene(kArmScene);
  const int wrist = scene.find_sensor("wrist");
  for (const Eigen::VectorXd& q : scene.sweep.stops) {
    const Survivors s = filter_sim_frame(scene, wrist, JointState{0.0, q, std::nullopt}, SelfFilterConfig{});
    EXPECT_EQ(s.survivors, 0u);
    // The padded flange reaches into the image's edge: measured 1.5 % of the table's points at most.
    EXPECT_LT(s.removed_elsewhere, s.other_points / 40) << s.other_points;
  }
}

TEST(SelfFilterTest, TheAbbIrb2400MeshesRemoveThemselves) {
  CELLMAP_SKIP_WITHOUT_DATA(kIrb2400);
  sim::Scene scene = sim::load_scene(kArmScene);
  Eigen::Isometry3d X_C_base = Eigen::Isometry3d::Identity();
  X_C_base.translation() = Eigen::Vector3d(1.5, -0.45, 0.5);
  scene.robot = UrdfModel::load(kIrb2400.string()).robot("tool0", X_C_base);
  scene.sensors.erase(scene.sensors.begin() + scene.find_sensor("wrist"));  // the arm cell's wrist pose is
                                                                            // the other arm's
  ASSERT_GT(scene.robot.triangle_count(), 1500u);
  const int post = scene.find_sensor("post");
  Eigen::VectorXd q(6);
  q << 0.3, 0.4, 0.2, 0.0, 0.6, 0.0;
  const Survivors s = filter_sim_frame(scene, post, JointState{0.0, q, std::nullopt}, SelfFilterConfig{});
  ASSERT_GT(s.robot_points, 800u);
  EXPECT_EQ(s.survivors, 0u) << s.robot_points;
  EXPECT_LE(s.mixed_kept, s.robot_points / 100);
  EXPECT_LT(s.removed_elsewhere, s.other_points / 20);
}

TEST(SelfFilterTest, EmptyAndNonFiniteInputAndASensorInsideThePadding) {
  const Robot robot = box_robot(kRobotBox);
  const SelfFilter filter(robot, SelfFilterConfig{});
  Rendered shot = render({kWall, kRobotBox}, Eigen::Isometry3d::Identity(), camera(40, 30));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  shot.frame.points_S.push_back(pcl::PointXYZ(nan, 0, 1));
  shot.frame.points_S.push_back(pcl::PointXYZ(0, 0, std::numeric_limits<float>::infinity()));
  SelfFilterResult result = filter.filter(shot.frame, at_rest(robot));
  EXPECT_EQ(result.kept + result.removed, shot.frame.points_S.size() - 2);
  EXPECT_GT(result.removed, 0u);
  // No points; a scanner frame without points.
  Frame empty = shot.frame;
  empty.points_S.clear();
  result = filter.filter(empty, at_rest(robot));
  EXPECT_EQ(result.kept + result.removed, 0u);
  empty.depth.reset();
  EXPECT_EQ(filter.filter(empty, at_rest(robot)).scan.clear_C.size(), 0u);
  // The wrong number of link poses, bad intrinsics.
  EXPECT_THROW((void)filter.filter(shot.frame, RobotAt{}), Error);
  Frame bad = shot.frame;
  bad.depth->intrinsics.fx = 0;
  EXPECT_THROW((void)filter.filter(bad, at_rest(robot)), Error);
  // A camera inside the padded robot would lose every point: the shape is skipped and counted instead.
  Frame inside = shot.frame;
  inside.X_CS.translation() = kRobotBox.centre + Eigen::Vector3d(0, 0, -0.22);
  result = filter.filter(inside, at_rest(robot));
  EXPECT_EQ(result.skipped_shapes, 1u);
  EXPECT_EQ(result.removed, 0u);
  // Disabled: to_scan.
  SelfFilterConfig off;
  off.enabled = false;
  result = SelfFilter(robot, off).filter(shot.frame, at_rest(robot));
  EXPECT_EQ(result.removed, 0u);
  EXPECT_EQ(result.scan.points_C.size(), to_scan(shot.frame).points_C.size());
}

TEST(SelfFilterTest, ConfigReadsItsSectionAndRefusesBadValues) {
  const SelfFilterConfig config =
      SelfFilterConfig::from_yaml(YamlMap::parse("enabled: false\npadding_scale: 1.1\npadding: 0.05\n", ""));
  EXPECT_FALSE(config.enabled);
  EXPECT_DOUBLE_EQ(config.padding_scale, 1.1);
  EXPECT_DOUBLE_EQ(config.padding, 0.05);
  EXPECT_THROW((void)SelfFilterConfig::from_yaml(YamlMap::parse("padding: -0.01\n", "")), Error);
  EXPECT_THROW((void)SelfFilterConfig::from_yaml(YamlMap::parse("padding_scale: 0.9\n", "")), Error);
  EXPECT_THROW((void)SelfFilterConfig::from_yaml(YamlMap::parse("pading: 0.1\n", "")), Error);
  EXPECT_THROW(SelfFilter(Robot::serial("base", {}), padding(1.0, 2.0)), Error);
}

}  // namespace
}  // namespace cellmap
