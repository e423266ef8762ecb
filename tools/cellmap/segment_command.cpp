// SPDX-License-Identifier: Apache-2.0
// `cellmap segment IN.{pcd,ply} [--pipeline cell|points] [--config FILE] [--boxes obb|aabb] -o OUT.json`: one
// cloud → boxes, by the cell pipeline's stages with cellmapd's config (default) or by the paper's point
// pipeline.
#include <chrono>
#include <iostream>
#include <memory>

#include "cellmap/boxes/box.hpp"
#include "cellmap/cell/cloud_boxes.hpp"
#include "cellmap/io/cloud_file.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "commands.hpp"
#include "daemon_config.hpp"

namespace cellmap::cli {
namespace {

struct SegmentArgs {
  std::string input, pipeline = "cell", config, boxes, output;
};

// The config is read before the cloud: a bad config fails fast, whatever the cloud.
void segment_as_cell(const SegmentArgs& args) {
  CellPipelineConfig config =
      args.config.empty()
          ? daemon::DaemonConfig::parse(daemon::default_config_yaml(), "cellmapd defaults", ".").pipeline
          : daemon::DaemonConfig::load(args.config).pipeline;
  if (!args.boxes.empty()) config.segment.box_kind = box_kind_from_string(args.boxes, "--boxes");
  const CloudFile file = load_cloud_file(args.input);
  const CloudBoxes result = boxes_of_cloud(file.points, config);
  write_box_file(args.output, result.boxes);
  std::cerr << "cellmap segment: " << args.input << ": " << file.non_finite << " NaN/inf points dropped; "
            << summary(result) << " -> " << args.output << "\n";
}

void segment_as_points(const SegmentArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  SegmentConfig config = args.config.empty() ? SegmentConfig{} : SegmentConfig::load(args.config);
  if (!args.boxes.empty()) config.box_kind = box_kind_from_string(args.boxes, "--boxes");
  const CloudFile file = load_cloud_file(args.input);
  const SegmentResult result = segment_cloud(file.points, config);
  write_box_file(args.output, result.boxes);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cerr << "cellmap segment: " << args.input << ": " << file.non_finite << " NaN/inf points dropped; "
            << summary(result.stats) << "; wall " << seconds << " s -> " << args.output << "\n";
}

}  // namespace

void add_segment_command(CLI::App& app) {
  auto args = std::make_shared<SegmentArgs>();
  CLI::App* command = app.add_subcommand(
      "segment",
      "Segment one point cloud (PCD/PLY, its own frame) into collision boxes (boxes JSON, version 1)");
  command->add_option("input", args->input, "point cloud file, .pcd or .ply")->required();
  command
      ->add_option("--pipeline", args->pipeline,
                   "cell: the cloud as cellmapd's settled map (occupied voxels, noise groups dropped, every "
                   "obstacle voxel boxed; its config); points: the paper's pipeline on the raw points")
      ->check(CLI::IsMember({"cell", "points"}));
  command->add_option("--config", args->config,
                      "parameters: a cellmapd config (config/cellmapd.yaml, laid over its defaults) for "
                      "--pipeline cell, a config/segment.yaml for --pipeline points");
  command->add_option("--boxes", args->boxes, "box kind, overrides the config: obb or aabb")
      ->check(CLI::IsMember({"obb", "aabb"}));
  command->add_option("-o,--output", args->output, "boxes JSON file to write")->required();
  command->callback([args] {
    if (args->pipeline == "cell") {
      segment_as_cell(*args);
    } else {
      segment_as_points(*args);
    }
  });
}

}  // namespace cellmap::cli
