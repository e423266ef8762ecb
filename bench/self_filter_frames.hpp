// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmap bench fusion, self-filter part: the filter's cost per frame against the fusion's cost for the same
// frame (the filtered one, as the daemon fuses it), and fusion with the filter's clear-only rays against
// fusion of the unfiltered frame. Frames: the arm cell's post camera with the arm working over the table,
// at native resolution (Kinect v2 512 × 424, RealSense D435 1280 × 720), noise on.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/self_filter/self_filter.hpp"
#include "cellmap/sim/scene.hpp"
#include "cellmap/sim/simulator.hpp"
#include "cellmap/urdf/urdf_model.hpp"
#include "ratio_report.hpp"

namespace cellmap::bench {

struct SelfFilterCase {
  Frame frame;
  RobotAt robot;
  std::shared_ptr<const SelfFilter> filter;
};

inline std::map<std::string, SelfFilterCase>& self_filter_cases() {
  static std::map<std::string, SelfFilterCase> cases;
  return cases;
}

// The arm cell with the IRB 2400 on the pedestal when the shared data has it (1 918 mesh triangles), else
// the project's arm.
inline sim::Scene self_filter_scene(std::string& robot_name) {
  sim::Scene scene = sim::load_scene(std::string(CELLMAP_SOURCE_DIR) + "/config/scenes/arm_cell.yaml");
  const std::filesystem::path irb2400 =
      std::filesystem::path(CELLMAP_SHARED_DATA) / "robots/abb_irb2400_support/urdf/irb2400.urdf";
  robot_name = "cellmap_arm";
  if (std::filesystem::exists(irb2400)) {
    Eigen::Isometry3d X_C_base = Eigen::Isometry3d::Identity();
    X_C_base.translation() = Eigen::Vector3d(1.5, -0.45, 0.5);
    scene.robot = UrdfModel::load(irb2400.string()).robot("tool0", X_C_base);
    robot_name = "irb2400";
    // The wrist camera's sweep plan is the other arm's (it would leave the cell); only the post camera is
    // used.
    scene.sensors.erase(scene.sensors.begin() + scene.find_sensor("wrist"));
  }
  return scene;
}

inline void BM_SelfFilter(benchmark::State& state, const std::string& name) {
  const SelfFilterCase& c = self_filter_cases().at(name);
  for (auto _ : state) benchmark::DoNotOptimize(c.filter->filter(c.frame, c.robot).removed);
}

inline void BM_FuseFrame(benchmark::State& state, const std::string& name, bool filtered) {
  const SelfFilterCase& c = self_filter_cases().at(name);
  Sweep sweep;
  sweep.scans.push_back(filtered ? c.filter->filter(c.frame, c.robot).scan : to_scan(c.frame));
  for (auto _ : state) {
    OccupancyMap map;
    map.integrate(sweep);
    benchmark::DoNotOptimize(map.tree().size());
  }
}

inline void add_self_filter_case(const std::string& name, const sim::Scene& scene, int sensor,
                                 const JointState& joints, std::shared_ptr<const SelfFilter> filter) {
  const sim::SimFrame shot = sim::Simulator(scene).render(sensor, joints, 0, 0);
  SelfFilterCase c{shot.frame, RobotAt{scene.robot.link_poses(joints.q), joints.payload}, std::move(filter)};
  std::size_t robot_pixels = 0;
  for (const int hit : shot.hit) robot_pixels += hit == sim::RayHit::kRobot;
  const SelfFilterResult result = c.filter->filter(c.frame, c.robot);
  std::printf("self_filter %s: %d x %d, %zu points, %zu robot pixels, %zu removed, %zu clear-only rays\n",
              name.c_str(), c.frame.depth->intrinsics.width, c.frame.depth->intrinsics.height,
              c.frame.points_S.size(), robot_pixels, result.removed, result.scan.clear_C.size());
  self_filter_cases()[name] = std::move(c);
}

// Registers the self-filter benchmarks and their ratios: "self_filter <camera>" = fusion time of the filtered
// frame / filter time (how many times cheaper the filter is than the fusion it precedes), and "fusion with
// clear-only rays <camera>" = fusion time of the unfiltered frame / fusion time of the filtered one.
inline void register_self_filter(std::vector<Ratio>& ratios) {
  std::string robot_name;
  sim::Scene scene = self_filter_scene(robot_name);
  const int post = scene.find_sensor("post");
  const auto filter = std::make_shared<const SelfFilter>(scene.robot, SelfFilterConfig{});
  std::printf("self_filter robot %s: %zu triangles rendered per frame (padding %.2f m)\n", robot_name.c_str(),
              filter->triangle_count(), filter->config().padding);
  Eigen::VectorXd q(6);
  q << 0.3, 0.4, 0.2, 0.0, 0.6, 0.0;  // reaching over the table, in the post camera's view
  Payload carton;
  carton.X_EB.translation() = Eigen::Vector3d(0, 0, 0.2);
  carton.half_extents = Eigen::Vector3d(0.2, 0.15, 0.15);
  const JointState joints{0.0, q, carton};
  sim::SensorSpec& spec = scene.sensors[std::size_t(post)];
  spec.intrinsics = sim::default_intrinsics(sim::SensorModel::kKinectV2);
  add_self_filter_case("kinect_v2_512x424", scene, post, joints, filter);
  spec.model = sim::SensorModel::kRealsenseD435;
  PinholeIntrinsics hd = sim::default_intrinsics(sim::SensorModel::kRealsenseD435);
  hd.width = 1280;
  hd.height = 720;
  hd.fx = hd.fy = 640.0;  // 87° horizontal field of view
  hd.cx = 639.5;
  hd.cy = 359.5;
  spec.intrinsics = hd;
  add_self_filter_case("realsense_1280x720", scene, post, joints, filter);

  for (const auto& entry : self_filter_cases()) {
    const std::string& name = entry.first;
    const std::string filter_name = "BM_SelfFilter/" + name;
    const std::string fused = "BM_FuseFilteredFrame/" + name;
    const std::string fused_raw = "BM_FuseUnfilteredFrame/" + name;
    benchmark::RegisterBenchmark(filter_name.c_str(), BM_SelfFilter, name)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime();
    benchmark::RegisterBenchmark(fused.c_str(), BM_FuseFrame, name, true)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime();
    benchmark::RegisterBenchmark(fused_raw.c_str(), BM_FuseFrame, name, false)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime();
    const std::string suffix = "/process_time";
    ratios.push_back({"self_filter " + name, filter_name + suffix, fused + suffix});
    ratios.push_back({"fusion with clear-only rays " + name, fused + suffix, fused_raw + suffix});
  }
}

}  // namespace cellmap::bench
