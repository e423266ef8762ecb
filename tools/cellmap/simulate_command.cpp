// SPDX-License-Identifier: Apache-2.0
// `cellmap simulate [SCENE.yaml] [--sensor NAME] [--seed N] [--exact] -o DIR`: one simulated sweep on disk,
// as a replay directory (replay_source.hpp) plus frames.csv (sensor poses and joint vectors) and the merged
// cloud.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "cellmap/common/error.hpp"
#include "cellmap/sensor/depth_io.hpp"
#include "cellmap/sensor/replay_source.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/recording.hpp"
#include "cellmap/sim/simulator.hpp"
#include "cellmap/sweep/sweep.hpp"
#include "commands.hpp"

namespace cellmap::cli {
namespace {

struct SimulateArgs {
  std::string scene;
  std::string sensor;
  long long seed = -1;
  bool exact = false;
  unsigned long long sweep_index = 0;
  std::string out;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void simulate(const SimulateArgs& args) {
  sim::Scene scene = args.scene.empty() ? sim::default_scene() : sim::load_scene(args.scene);
  const int index = args.sensor.empty() ? 0 : scene.find_sensor(args.sensor);
  if (index < 0) {
    std::string known;
    for (const sim::SensorSpec& s : scene.sensors)
      known += (known.empty() ? "" : ", ") + s.name + " (" + to_string(s.model) + ")";
    throw Error("simulate: --sensor " + args.sensor + ": the scene has no such sensor or model; it has " +
                known);
  }
  if (args.seed >= 0)
    scene.sensors[static_cast<std::size_t>(index)].seed = static_cast<std::uint64_t>(args.seed);
  const sim::SensorSpec spec = scene.sensors[static_cast<std::size_t>(index)];
  const std::vector<std::string> joint_names = scene.robot.joint_names();

  sim::SimOptions options;
  options.noise = !args.exact;
  const sim::Simulator simulator(std::move(scene), options);

  const auto render_start = std::chrono::steady_clock::now();
  const std::vector<sim::SimFrame> frames = simulator.sweep(index, args.sweep_index);
  const double render_seconds = seconds_since(render_start);

  const auto write_start = std::chrono::steady_clock::now();
  const std::filesystem::path dir = args.out;
  std::vector<Frame> plain;
  std::vector<sim::PoseRecord> records;
  std::vector<ReplayEntry> replay;
  const Eigen::Isometry3d X_SE = spec.X_ES.inverse();
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const Frame& frame = frames[k].frame;
    char name[64];
    std::snprintf(name, sizeof name, "frames/%s_%04zu.%s", spec.name.c_str(), k, frame.depth ? "png" : "pcd");
    if (frame.depth) {
      write_depth_png((dir / name).string(), RawDepth{frame.depth->intrinsics.width,
                                                      frame.depth->intrinsics.height, frame.depth->depth});
    } else {
      sim::write_pcd(dir / name, frame.points_S);
    }
    records.push_back(sim::PoseRecord{k, spec.name, frame.stamp, name, frame.X_CS, frames[k].q});
    replay.push_back(ReplayEntry{name, frame.stamp, frame.X_CS * X_SE});  // the replay format holds X_CE
    plain.push_back(frame);
  }
  if (spec.is_camera()) sim::write_intrinsics(dir / "intrinsics.yaml", spec.intrinsics);
  write_replay_poses((dir / "poses.csv").string(), replay);
  sim::write_poses(dir / "frames.csv", records, joint_names);
  const Sweep sweep = merge_frames(plain);
  sim::write_sweep_pcd(dir / "merged.pcd", sweep);
  const double write_seconds = seconds_since(write_start);

  std::fprintf(stderr,
               "simulate: sensor %s (%s%s), %zu frames, %zu points merged in the cell frame; render %.3f s, "
               "write %.3f s; wrote %s/{frames/, poses.csv, frames.csv, merged.pcd}\n",
               spec.name.c_str(), to_string(spec.model).c_str(), args.exact ? ", exact" : "", frames.size(),
               sweep.point_count(), render_seconds, write_seconds, dir.string().c_str());
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "simulate",
      "Simulate one sweep of a scene into a replay directory: per-frame 16-bit PNG depth (or PCD scans), "
      "poses.csv (tool poses), frames.csv (sensor poses, joints), merged.pcd (cell frame, with origins)");
  auto args = std::make_shared<SimulateArgs>();
  sub->add_option("scene", args->scene, "scene YAML (default: the embedded config/cell.yaml)");
  sub->add_option(
      "--sensor", args->sensor,
      "sensor name or model from the scene: kinect_v2 | realsense_d435 | os32c (default: the first)");
  sub->add_option("--seed", args->seed, "noise seed (default: the scene's)")->check(CLI::NonNegativeNumber);
  sub->add_flag("--exact", args->exact, "zero-noise mode: exact depths, only quantized");
  sub->add_option("--sweep-index", args->sweep_index, "which sweep (keys the noise; default 0)");
  sub->add_option("-o,--output", args->out, "output directory")->required();
  sub->callback([args] { simulate(*args); });
}

}  // namespace cellmap::cli
