// SPDX-License-Identifier: Apache-2.0
// Simulated camera frames: one 640×480 frame of the default cell (its 17 obstacles plus 13 more = 30),
// rendered by the simulator (tile culling, 2 threads, noise, quantization, back-projection) against the
// anchor: the same rays cast one by one against every obstacle on one thread (what a straightforward caster
// does). And the robot's cost: a native 512×424 Kinect frame of the arm cell from the post camera with the
// arm in view (cellmap's arm, or the ABB IRB 2400's 1 918 mesh triangles) against the same frame without the
// robot.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/simulator.hpp"
#include "ratio_report.hpp"

namespace {

using namespace cellmap::sim;

Scene bench_scene() {
  Scene scene = default_scene();
  // 13 more boxes, cylinders and spheres on the table: 30 primitives in all.
  for (int i = 0; i < 13; ++i) {
    Obstacle o;
    o.name = "extra_" + std::to_string(i);
    const double x = 0.3 + 0.2 * i, y = (i % 2) ? 0.15 : 1.85;
    if (i % 3 == 0) o.shape = BoxShape{Eigen::Vector3d(0.06, 0.05, 0.08)};
    if (i % 3 == 1) o.shape = CylinderShape{0.05, 0.16};
    if (i % 3 == 2) o.shape = SphereShape{0.07};
    o.X_CO.translation() = Eigen::Vector3d(x, y, 0.83);
    scene.obstacles.push_back(o);
  }
  // The RealSense at its native 640×480 mode.
  SensorSpec& cam = scene.sensors[static_cast<std::size_t>(scene.find_sensor("realsense_d435"))];
  cam.intrinsics = default_intrinsics(SensorModel::kRealsenseD435);
  return scene;
}

void BM_SimulatorFrame640x480(benchmark::State& state) {
  const Scene scene = bench_scene();
  SimOptions options;
  options.threads = static_cast<int>(state.range(0));
  options.noise = state.range(1) != 0;
  const Simulator simulator(scene, options);
  const int cam = scene.find_sensor("realsense_d435");
  std::uint64_t frame = 0;
  for (auto _ : state) {
    SimFrame f = simulator.render(cam, scene.sweep.stops[2], 0.0, 0, frame++);
    benchmark::DoNotOptimize(f.frame.points_S.size());
  }
  state.counters["obstacles"] = static_cast<double>(scene.obstacles.size());
}
BENCHMARK(BM_SimulatorFrame640x480)
    ->ArgNames({"threads", "noise"})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Args({1, 0})
    ->Unit(benchmark::kMillisecond);

void BM_NaiveCast640x480(benchmark::State& state) {
  const Scene scene = bench_scene();
  const int cam = scene.find_sensor("realsense_d435");
  const cellmap::PinholeIntrinsics& k = scene.sensors[static_cast<std::size_t>(cam)].intrinsics;
  const Eigen::Isometry3d X_CS = scene.sensor_pose(cam, scene.sweep.stops[2]);
  const SceneCaster caster(scene.obstacles);
  for (auto _ : state) {
    double sum = 0;
    for (int v = 0; v < k.height; ++v) {
      for (int u = 0; u < k.width; ++u) {
        const Eigen::Vector3d d_C =
            X_CS.linear() * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0).normalized();
        sum += caster.cast(X_CS.translation(), d_C, k.max_range).t;
      }
    }
    benchmark::DoNotOptimize(sum);
  }
}
BENCHMARK(BM_NaiveCast640x480)->Unit(benchmark::kMillisecond);

// The arm cell with the post camera at the Kinect's native mode; `abb` swaps in the IRB 2400 (shared data).
Scene arm_scene(bool abb) {
  const std::string dir = std::string(CELLMAP_SOURCE_DIR) + "/config/scenes";
  std::string text = cellmap::read_file(dir + "/arm_cell.yaml");
  if (abb) {
    const std::string from = "../robots/cellmap_arm/urdf/cellmap_arm.urdf";
    text.replace(text.find(from), from.size(),
                 std::string(CELLMAP_SHARED_DATA) + "/robots/abb_irb2400_support/urdf/irb2400.urdf");
  }
  Scene scene = parse_scene(text, "arm_cell.yaml", dir);
  SensorSpec& post = scene.sensors[static_cast<std::size_t>(scene.find_sensor("post"))];
  post.intrinsics = default_intrinsics(SensorModel::kKinectV2);
  post.intrinsics.fx = post.intrinsics.fy = 365.0;
  return scene;
}

// Arguments: robot (0 = not rendered, 1 = cellmap's arm, 2 = the IRB 2400).
void BM_ArmCellFrame512x424(benchmark::State& state) {
  const bool abb = state.range(0) == 2;
  if (abb && !std::filesystem::exists(std::string(CELLMAP_SHARED_DATA) + "/robots")) {
    state.SkipWithError("no robot descriptions in the shared data");
    return;
  }
  const Scene scene = arm_scene(abb);
  SimOptions options;
  options.threads = 1;
  options.render_robot = state.range(0) != 0;
  const Simulator simulator(scene, options);
  const int post = scene.find_sensor("post");
  std::uint64_t frame = 0;
  std::size_t robot_pixels = 0;
  for (auto _ : state) {
    SimFrame f = simulator.render(post, scene.sweep.stops[2], 0.0, 0, frame++);
    robot_pixels = static_cast<std::size_t>(std::count(f.hit.begin(), f.hit.end(), RayHit::kRobot));
    benchmark::DoNotOptimize(f.frame.points_S.size());
  }
  state.counters["triangles"] = static_cast<double>(scene.robot.triangle_count());
  state.counters["robot_pixels"] = static_cast<double>(robot_pixels);
}
BENCHMARK(BM_ArmCellFrame512x424)->ArgNames({"robot"})->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return cellmap::bench::run_and_report(
      argc, argv,
      {{"sim_frame_640x480_2_threads", "BM_SimulatorFrame640x480/threads:2/noise:1", "BM_NaiveCast640x480"},
       {"sim_frame_640x480_1_thread", "BM_SimulatorFrame640x480/threads:1/noise:1", "BM_NaiveCast640x480"},
       {"sim_frame_640x480_1_thread_exact", "BM_SimulatorFrame640x480/threads:1/noise:0",
        "BM_NaiveCast640x480"},
       {"arm_frame_with_arm_vs_without", "BM_ArmCellFrame512x424/robot:1", "BM_ArmCellFrame512x424/robot:0"},
       {"arm_frame_with_irb2400_vs_without", "BM_ArmCellFrame512x424/robot:2",
        "BM_ArmCellFrame512x424/robot:0"}});
}
