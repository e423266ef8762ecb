// `cellmap segment IN.{pcd,ply} [--config FILE] [--boxes obb|aabb] -o OUT.json`: the batch pipeline on one
// cloud.
#include <chrono>
#include <iostream>
#include <memory>

#include "cellmap/boxes/box.hpp"
#include "cellmap/io/cloud_file.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "commands.hpp"

namespace cellmap::cli {

void add_segment_command(CLI::App& app) {
  struct Options {
    std::string input, config, boxes, output;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "segment",
      "Segment one point cloud (PCD/PLY, its own frame) into collision boxes (boxes JSON, version 1)");
  command->add_option("input", options->input, "point cloud file, .pcd or .ply")->required();
  command->add_option("--config", options->config, "pipeline parameters (YAML, see config/segment.yaml)");
  command->add_option("--boxes", options->boxes, "box kind, overrides the config: obb or aabb")
      ->check(CLI::IsMember({"obb", "aabb"}));
  command->add_option("-o,--output", options->output, "boxes JSON file to write")->required();
  command->callback([options] {
    const auto start = std::chrono::steady_clock::now();
    SegmentConfig config = options->config.empty() ? SegmentConfig{} : load_segment_config(options->config);
    if (!options->boxes.empty()) config.box_kind = box_kind_from_string(options->boxes, "--boxes");
    const CloudFile file = load_cloud_file(options->input);
    const SegmentResult result = segment_cloud(file.points, config);
    write_box_file(options->output, result.boxes);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cerr << "cellmap segment: " << options->input << ": " << file.non_finite
              << " NaN/inf points dropped; " << summary(result.stats) << "; wall " << seconds << " s -> "
              << options->output << "\n";
  });
}

}  // namespace cellmap::cli
