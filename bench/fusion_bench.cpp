// SPDX-License-Identifier: Apache-2.0
// cellmap bench fusion: our sweep fusion (OccupancyMap::integrate) against OctoMap's own
// OcTree::insertPointCloud on the same frames, in the same run. Each frame is one sweep; a frame set is fused
// into a fresh map per iteration. Prints the voxel-state agreement of the resulting maps before the timings.
// Frame sets: the real grabber frames, a synthetic box room, and one sweep of the default simulated cell
// (config/cell.yaml) at each camera's native resolution (Kinect v2 512 × 424, RealSense D435 848 × 480),
// rendered at start with the cameras' noise.
// Then the self filter's cost per frame against the fusion of that frame, at native camera resolution with
// the ABB IRB 2400 (or, without the shared data, cellmap's own arm) in view of a fixed camera.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/simulator.hpp"
#include "native_modes.hpp"
#include "occupancy/box_scene.hpp"
#include "occupancy/grabber_scans.hpp"
#include "ratio_report.hpp"
#include "self_filter_frames.hpp"
#include "tree_agreement.hpp"

namespace {

using cellmap::OccupancyConfig;
using cellmap::OccupancyMap;
using cellmap::Sweep;

// The frame sets, each a list of one-scan sweeps (camera frame = cell frame, identity pose).
std::map<std::string, std::vector<Sweep>>& frame_sets() {
  static std::map<std::string, std::vector<Sweep>> sets;
  return sets;
}

octomap::Pointcloud to_octomap(const cellmap::Scan& scan) {
  octomap::Pointcloud cloud;
  cloud.reserve(scan.points_C.size());
  for (const auto& p : scan.points_C.points) {
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) cloud.push_back(p.x, p.y, p.z);
  }
  return cloud;
}

octomap::point3d origin_of(const cellmap::Scan& scan) {
  return octomap::point3d(float(scan.origin_C.x()), float(scan.origin_C.y()), float(scan.origin_C.z()));
}

void fuse_ours(const std::vector<Sweep>& sweeps, OccupancyMap& map) {
  for (const Sweep& sweep : sweeps) map.integrate(sweep);
}

void fuse_octomap(const std::vector<Sweep>& sweeps, const std::vector<octomap::Pointcloud>& clouds,
                  bool discretize, octomap::OcTree& tree, double max_range) {
  for (std::size_t i = 0; i < sweeps.size(); ++i) {
    tree.insertPointCloud(clouds[i], origin_of(sweeps[i].scans.front()), max_range, false, discretize);
  }
}

void BM_FusionOurs(benchmark::State& state, const std::string& set) {
  const std::vector<Sweep>& sweeps = frame_sets().at(set);
  for (auto _ : state) {
    OccupancyMap map;
    fuse_ours(sweeps, map);
    benchmark::DoNotOptimize(map.tree().size());
  }
}

void BM_FusionOctomap(benchmark::State& state, const std::string& set, bool discretize) {
  const std::vector<Sweep>& sweeps = frame_sets().at(set);
  std::vector<octomap::Pointcloud> clouds;
  for (const Sweep& sweep : sweeps) clouds.push_back(to_octomap(sweep.scans.front()));
  const OccupancyConfig config;
  for (auto _ : state) {
    octomap::OcTree tree(config.resolution);
    cellmap::apply_sensor_model(config, tree);
    fuse_octomap(sweeps, clouds, discretize, tree, config.max_range);
    benchmark::DoNotOptimize(tree.size());
  }
}

// Each real frame is a sweep of its own.
std::vector<Sweep> grabber_frames() {
  std::vector<Sweep> sweeps;
  for (cellmap::Scan& scan : cellmap::testing::grabber_scans(CELLMAP_SHARED_DATA)) {
    sweeps.emplace_back();
    sweeps.back().scans.push_back(std::move(scan));
  }
  return sweeps;
}

std::vector<Sweep> synthetic_frame() {
  Sweep sweep;
  sweep.scans.push_back(cellmap::testing::render_scan(
      cellmap::testing::box_room(), Eigen::Isometry3d::Identity(), cellmap::testing::kinect_intrinsics()));
  return {sweep};
}

// One sweep of the default cell's `model` camera in the native mode `intrinsics`, each frame a sweep of its
// own.
std::vector<Sweep> native_cell_frames(cellmap::sim::SensorModel model,
                                      const cellmap::PinholeIntrinsics& intrinsics) {
  cellmap::sim::Scene scene = cellmap::sim::default_scene();
  std::size_t sensor = 0;
  while (scene.sensors[sensor].model != model) ++sensor;
  scene.sensors[sensor].intrinsics = intrinsics;
  std::vector<Sweep> sweeps;
  for (const cellmap::sim::SimFrame& frame : cellmap::sim::Simulator(scene).sweep(int(sensor))) {
    sweeps.emplace_back();
    sweeps.back().scans.push_back(cellmap::to_scan(frame.frame));
  }
  return sweeps;
}

void print_agreement(const std::string& set) {
  const std::vector<Sweep>& sweeps = frame_sets().at(set);
  std::vector<octomap::Pointcloud> clouds;
  std::size_t points = 0;
  for (const Sweep& sweep : sweeps) {
    clouds.push_back(to_octomap(sweep.scans.front()));
    points += clouds.back().size();
  }
  const OccupancyConfig config;
  OccupancyMap ours(config);
  fuse_ours(sweeps, ours);
  for (const bool discretize : {true, false}) {
    octomap::OcTree reference(config.resolution);
    cellmap::apply_sensor_model(config, reference);
    fuse_octomap(sweeps, clouds, discretize, reference, config.max_range);
    const cellmap::TreeAgreement a = cellmap::compare_trees(ours.tree(), reference);
    std::printf(
        "agreement fusion %s vs insertPointCloud(discretize=%s): %.4f %% of %zu voxels "
        "(occupied: ours %zu, octomap %zu, both %zu; %zu frames, %zu valid points)\n",
        set.c_str(), discretize ? "true" : "false", 100.0 * a.fraction(), a.voxels, a.occupied_a,
        a.occupied_b, a.occupied_both, sweeps.size(), points);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<cellmap::bench::Ratio> ratios;
  std::vector<Sweep> grabber = grabber_frames();
  if (grabber.empty()) {
    std::printf("fusion bench: %s/pcl/grabber_sequence is absent; only the synthetic frame runs\n",
                CELLMAP_SHARED_DATA);
  } else {
    frame_sets()["grabber_3frames"] = std::move(grabber);
  }
  frame_sets()["synthetic_1frame"] = synthetic_frame();
  using cellmap::sim::SensorModel;
  frame_sets()["cell_kinect_v2_512x424"] =
      native_cell_frames(SensorModel::kKinectV2, cellmap::sim::default_intrinsics(SensorModel::kKinectV2));
  frame_sets()["cell_d435_848x480"] =
      native_cell_frames(SensorModel::kRealsenseD435, cellmap::bench::d435_848x480());

  for (const auto& entry : frame_sets()) {
    const std::string& name = entry.first;
    print_agreement(name);
    const std::string ours = "BM_FusionOurs/" + name;
    const std::string anchor = "BM_FusionOctomap/" + name;
    const std::string anchor_discrete = "BM_FusionOctomapDiscretized/" + name;
    // Process CPU time, so that the CPU column counts our worker threads too; ratios use wall time.
    benchmark::RegisterBenchmark(ours.c_str(), BM_FusionOurs, name)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime();
    benchmark::RegisterBenchmark(anchor.c_str(), BM_FusionOctomap, name, false)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime();
    benchmark::RegisterBenchmark(anchor_discrete.c_str(), BM_FusionOctomap, name, true)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime();
    // Google Benchmark names process-time runs "<name>/process_time".
    const std::string suffix = "/process_time";
    ratios.push_back({"fusion " + name, ours + suffix, anchor + suffix});
    ratios.push_back(
        {"fusion " + name + " (vs discretized insert)", ours + suffix, anchor_discrete + suffix});
  }
  cellmap::bench::register_self_filter(ratios);
  return cellmap::bench::run_and_report(argc, argv, ratios);
}
