// `cellmap sensor-comparison [SCENE.yaml] [--config SEG.yaml] [--voxel M] [--region ...] -o DIR`: the paper's
// sensor comparison on a simulated cell. Every sensor of the scene sweeps the same cell; its merged cloud
// goes through the batch pipeline (cellmap segment's library call) and the boxes are scored against the
// scene's true obstacles: coverage of the surface the sensor saw (its own exact sweep) and lost free space.
#include <pcl/filters/voxel_grid.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/research/evaluate.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/simulator.hpp"
#include "cellmap/sweep/sweep.hpp"
#include "commands.hpp"
#include "parse.hpp"

namespace cellmap::cli {
namespace {

struct ComparisonArgs {
  std::string scene;
  std::string config;
  std::string boxes;
  double voxel = 0.02;
  std::string region = "0,0,0.76,3,2,2";
  std::string out;
};

struct Row {
  std::string sensor, model;
  std::size_t points = 0, points_used = 0;
  double seconds = 0;
  sim::BoxScore score;
};

// The merged cloud of one sweep; its sensor_origin_ is the mean sensor position (the pipeline orients normals
// towards it: every stop looks down at the table from above).
Cloud merged_cloud(const std::vector<sim::SimFrame>& frames) {
  std::vector<Frame> plain;
  for (const sim::SimFrame& f : frames) plain.push_back(f.frame);
  const Sweep sweep = merge_frames(plain);
  Cloud cloud = sweep.merged();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Scan& scan : sweep.scans) mean += scan.origin_C / static_cast<double>(sweep.scans.size());
  cloud.sensor_origin_ = Eigen::Vector4f(static_cast<float>(mean.x()), static_cast<float>(mean.y()),
                                         static_cast<float>(mean.z()), 0.0f);
  return cloud;
}

// Same density for every sensor (a camera sweep has 10× the points of the line scanner): one point per voxel.
Cloud downsampled(const Cloud& cloud, double voxel) {
  if (voxel <= 0) return cloud;
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(cloud.makeShared());
  grid.setLeafSize(static_cast<float>(voxel), static_cast<float>(voxel), static_cast<float>(voxel));
  Cloud out;
  grid.filter(out);
  out.sensor_origin_ = cloud.sensor_origin_;
  return out;
}

std::string percent(double share) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %%", 100.0 * share);
  return text;
}

std::string table(const std::vector<Row>& rows) {
  std::ostringstream out;
  out << "| sensor | model | points (used) | boxes | coverage | lost free space | blocked free space | "
         "segment time |\n"
      << "|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.2f s", r.seconds);
    out << "| " << r.sensor << " | " << r.model << " | " << r.points << " (" << r.points_used << ") | "
        << r.score.boxes << " | " << percent(r.score.coverage) << " | " << percent(r.score.lost_free_space)
        << " | " << percent(r.score.blocked_free_space) << " | " << seconds << " |\n";
  }
  return out.str();
}

std::string csv(const std::vector<Row>& rows) {
  std::ostringstream out;
  out << "sensor;model;points;points_used;boxes;coverage;lost_free_space;blocked_free_space;true_volume;box_"
         "volume;"
         "segment_seconds\n";
  for (const Row& r : rows) {
    out << r.sensor << ";" << r.model << ";" << r.points << ";" << r.points_used << ";" << r.score.boxes
        << ";" << r.score.coverage << ";" << r.score.lost_free_space << ";" << r.score.blocked_free_space
        << ";" << r.score.true_volume << ";" << r.score.box_volume << ";" << r.seconds << "\n";
  }
  return out.str();
}

// Three bar charts side by side: coverage (higher is safer), lost free space (signed: boxes smaller than the
// objects give negative values) and blocked free space (box volume outside every object; lower leaves more
// workspace to the planner).
std::string svg(const std::vector<Row>& rows, const std::string& caption) {
  const double panel_w = 240, panel_h = 220, left = 60, top = 40, bar_w = 44, gap = 28;
  const char* colours[] = {"#4477aa", "#ee6677", "#228833", "#ccbb44", "#66ccee"};
  std::ostringstream out;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << 3 * (panel_w + left) + 20 << "\" height=\""
      << panel_h + top + 70 << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  // One panel from `low` to `high` (shares), bars drawn from the zero line.
  auto panel = [&](double x0, const std::string& title, auto value) {
    double low = 0, high = 0.1;
    for (const Row& r : rows) low = std::min(low, value(r)), high = std::max(high, value(r));
    low = std::floor(low * 4) / 4, high = std::ceil(high * 4) / 4;  // axis at quarter steps
    auto y_of = [&](double v) { return top + panel_h * (high - v) / (high - low); };
    out << "<text x=\"" << x0 + panel_w / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"13\">" << title
        << "</text>\n";
    const double step = high - low <= 2.0 ? 0.25 : 0.5;
    for (double v = low; v <= high + 1e-9; v += step) {
      out << "<line x1=\"" << x0 << "\" x2=\"" << x0 + panel_w << "\" y1=\"" << y_of(v) << "\" y2=\""
          << y_of(v) << "\" stroke=\"#ddd\"/>\n<text x=\"" << x0 - 6 << "\" y=\"" << y_of(v) + 4
          << "\" text-anchor=\"end\">" << percent(v) << "</text>\n";
    }
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const double v = value(rows[i]);
      const double x = x0 + gap + static_cast<double>(i) * (bar_w + gap);
      const double y0 = y_of(std::max(v, 0.0)), y1 = y_of(std::min(v, 0.0));
      out << "<rect x=\"" << x << "\" y=\"" << y0 << "\" width=\"" << bar_w << "\" height=\"" << y1 - y0
          << "\" fill=\"" << colours[i % 5] << "\"/>\n<text x=\"" << x + bar_w / 2 << "\" y=\""
          << (v >= 0 ? y0 - 4 : y1 + 14) << "\" text-anchor=\"middle\">" << percent(v)
          << "</text>\n<text x=\"" << x + bar_w / 2 << "\" y=\"" << top + panel_h + 16
          << "\" text-anchor=\"middle\" font-size=\"10\">" << rows[i].model << "</text>\n";
    }
    out << "<line x1=\"" << x0 << "\" x2=\"" << x0 << "\" y1=\"" << top << "\" y2=\"" << top + panel_h
        << "\" stroke=\"black\"/>\n<line x1=\"" << x0 << "\" x2=\"" << x0 + panel_w << "\" y1=\"" << y_of(0)
        << "\" y2=\"" << y_of(0) << "\" stroke=\"black\"/>\n";
  };
  panel(left, "coverage of the seen surface", [](const Row& r) { return r.score.coverage; });
  panel(2 * left + panel_w, "lost free space", [](const Row& r) { return r.score.lost_free_space; });
  panel(3 * left + 2 * panel_w, "blocked free space",
        [](const Row& r) { return r.score.blocked_free_space; });
  out << "<text x=\"" << left << "\" y=\"" << top + panel_h + 50 << "\" font-size=\"11\">" << caption
      << "</text>\n</svg>\n";
  return out.str();
}

void compare(const ComparisonArgs& args) {
  const sim::Scene scene = args.scene.empty() ? sim::default_scene() : sim::load_scene(args.scene);
  SegmentConfig config = args.config.empty() ? SegmentConfig{} : load_segment_config(args.config);
  if (!args.boxes.empty()) config.box_kind = box_kind_from_string(args.boxes, "--boxes");
  const std::vector<double> r = parse_numbers(args.region, "--region", {6});
  const Region region{Eigen::Vector3d(r[0], r[1], r[2]), Eigen::Vector3d(r[3], r[4], r[5])};

  const sim::Simulator noisy(scene, sim::SimOptions{true, 2});
  const sim::Simulator exact(scene, sim::SimOptions{false, 2});
  std::vector<Row> rows;
  for (std::size_t i = 0; i < scene.sensors.size(); ++i) {
    const int index = static_cast<int>(i);
    Row row;
    row.sensor = scene.sensors[i].name;
    row.model = to_string(scene.sensors[i].model);
    const Cloud cloud = merged_cloud(noisy.sweep(index));
    const Cloud used = downsampled(cloud, args.voxel);
    row.points = cloud.size();
    row.points_used = used.size();
    const auto start = std::chrono::steady_clock::now();
    const SegmentResult result = segment_cloud(used, config);
    row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const Cloud truth = merged_cloud(exact.sweep(index));
    row.score = sim::score_boxes(scene.obstacles, result.boxes.boxes, truth, region);
    std::cerr << "sensor-comparison: " << row.sensor << ": " << summary(result.stats) << "\n";
    write_box_file(std::filesystem::path(args.out) / (row.sensor + "_boxes.json"), result.boxes);
    rows.push_back(row);
  }
  const std::filesystem::path dir = args.out;
  write_file_atomically(dir / "comparison.md", table(rows));
  write_file_atomically(dir / "comparison.csv", csv(rows));
  write_file_atomically(dir / "comparison.svg",
                        svg(rows,
                            "Simulated cell, one sweep per sensor, batch pipeline (cellmap segment), "
                            "boxes scored against the true obstacles above the table"));
  std::cout << table(rows);
}

}  // namespace

void add_sensor_comparison_command(CLI::App& app) {
  auto* sub =
      app.add_subcommand("sensor-comparison",
                         "The paper's sensor comparison on a simulated cell: each sensor's sweep through "
                         "the batch pipeline, boxes scored against the true obstacles (table + SVG)");
  auto args = std::make_shared<ComparisonArgs>();
  sub->add_option("scene", args->scene, "scene YAML (default: the embedded config/cell.yaml)");
  sub->add_option("--config", args->config, "segmentation parameters (YAML, see config/segment.yaml)");
  sub->add_option("--boxes", args->boxes, "box kind, overrides the config: obb or aabb")
      ->check(CLI::IsMember({"obb", "aabb"}));
  sub->add_option("--voxel", args->voxel, "downsample every merged cloud to one point per voxel (m; 0 = off)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--region", args->region,
                  "evaluation region xmin,ymin,zmin,xmax,ymax,zmax (default: above the table of cell.yaml)");
  sub->add_option("-o,--output", args->out, "output directory")->required();
  sub->callback([args] { compare(*args); });
}

}  // namespace cellmap::cli
