// Simulated camera frames: one 640×480 frame of the default cell (its 17 obstacles plus 13 more = 30),
// rendered by the simulator (tile culling, 2 threads, noise, quantization, back-projection) against the
// anchor: the same rays cast one by one against every obstacle on one thread (what a straightforward caster
// does).
#include <benchmark/benchmark.h>

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

}  // namespace

int main(int argc, char** argv) {
  return cellmap::bench::run_and_report(
      argc, argv,
      {{"sim_frame_640x480_2_threads", "BM_SimulatorFrame640x480/threads:2/noise:1", "BM_NaiveCast640x480"},
       {"sim_frame_640x480_1_thread", "BM_SimulatorFrame640x480/threads:1/noise:1", "BM_NaiveCast640x480"},
       {"sim_frame_640x480_1_thread_exact", "BM_SimulatorFrame640x480/threads:1/noise:0",
        "BM_NaiveCast640x480"}});
}
