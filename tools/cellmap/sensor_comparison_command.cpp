// SPDX-License-Identifier: Apache-2.0
// `cellmap sensor-comparison [SCENE.yaml] [--pipeline cell|points] [--config FILE] [--voxel M] [--region ...]
// -o DIR`: the paper's sensor comparison on a simulated cell. Every sensor of the scene sweeps the same cell;
// its merged cloud goes through the batch path (cellmap segment's library calls) and the boxes are scored
// against the scene's true obstacles: coverage of the surface the sensor saw (its own exact sweep), lost and
// blocked free space.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/research/sensor_comparison.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "commands.hpp"
#include "daemon_config.hpp"
#include "parse.hpp"

namespace cellmap::cli {
namespace {

struct ComparisonArgs {
  std::string scene;
  std::string pipeline = "cell";
  std::string config;
  std::string boxes;
  double voxel = 0.02;
  std::string region = "0,0,0.76,3,2,2";
  std::string out;
};

void compare(const ComparisonArgs& args) {
  const sim::Scene scene = args.scene.empty() ? sim::default_scene() : sim::load_scene(args.scene);
  sim::SensorComparisonConfig config;
  if (args.pipeline == "cell") {
    config.cell =
        args.config.empty()
            ? daemon::DaemonConfig::parse(daemon::default_config_yaml(), "cellmapd defaults", ".").pipeline
            : daemon::DaemonConfig::load(args.config).pipeline;
    if (!args.boxes.empty()) config.cell->segment.box_kind = box_kind_from_string(args.boxes, "--boxes");
  } else {
    if (!args.config.empty()) config.segment = SegmentConfig::load(args.config);
    if (!args.boxes.empty()) config.segment.box_kind = box_kind_from_string(args.boxes, "--boxes");
  }
  config.voxel = args.voxel;
  const std::vector<double> r = parse_numbers(args.region, "--region", {6});
  config.region = Region{Eigen::Vector3d(r[0], r[1], r[2]), Eigen::Vector3d(r[3], r[4], r[5])};

  const std::vector<sim::SensorComparisonRow> rows = sim::compare_sensors(scene, config);
  const std::filesystem::path dir = args.out;
  for (const sim::SensorComparisonRow& row : rows) {
    std::cerr << "sensor-comparison: " << row.sensor << ": " << row.summary << "\n";
    write_box_file(dir / (row.sensor + "_boxes.json"), row.boxes);
  }
  write_file_atomically(dir / "comparison.md", sim::sensor_comparison_table(rows));
  write_file_atomically(dir / "comparison.csv", sim::sensor_comparison_csv(rows));
  write_file_atomically(
      dir / "comparison.svg",
      sim::sensor_comparison_svg(rows, "Simulated cell, one sweep per sensor, cellmap segment --pipeline " +
                                           args.pipeline +
                                           ", boxes scored against the true obstacles above the table"));
  std::cout << sim::sensor_comparison_table(rows);
}

}  // namespace

void add_sensor_comparison_command(CLI::App& app) {
  auto* sub =
      app.add_subcommand("sensor-comparison",
                         "The paper's sensor comparison on a simulated cell: each sensor's sweep through "
                         "the batch pipeline, boxes scored against the true obstacles (table + SVG)");
  auto args = std::make_shared<ComparisonArgs>();
  sub->add_option("scene", args->scene, "scene YAML (default: the embedded config/cell.yaml)");
  sub->add_option("--pipeline", args->pipeline,
                  "cell: each cloud as cellmapd's settled map (its stages and config); points: the "
                  "paper's pipeline on the downsampled points")
      ->check(CLI::IsMember({"cell", "points"}));
  sub->add_option("--config", args->config,
                  "parameters: a cellmapd config for --pipeline cell, a config/segment.yaml for --pipeline "
                  "points");
  sub->add_option("--boxes", args->boxes, "box kind, overrides the config: obb or aabb")
      ->check(CLI::IsMember({"obb", "aabb"}));
  sub->add_option("--voxel", args->voxel,
                  "--pipeline points: downsample every merged cloud to one point per voxel (m; 0 = off)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--region", args->region,
                  "evaluation region xmin,ymin,zmin,xmax,ymax,zmax (default: above the table of cell.yaml)");
  sub->add_option("-o,--output", args->out, "output directory")->required();
  sub->callback([args] { compare(*args); });
}

}  // namespace cellmap::cli
