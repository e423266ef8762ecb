// SPDX-License-Identifier: Apache-2.0
#include "cellmap/research/sensor_comparison.hpp"

#include <pcl/filters/voxel_grid.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <sstream>

#include "cellmap/cell/cloud_boxes.hpp"
#include "cellmap/sim/simulator.hpp"
#include "cellmap/sweep/sweep.hpp"
#include "svg_plot.hpp"

namespace cellmap::sim {
namespace {

// The merged cloud of one sweep; its sensor_origin_ is the mean sensor position (the pipeline orients normals
// towards it: every stop looks down at the table from above).
Cloud merged_cloud(const std::vector<SimFrame>& frames) {
  std::vector<Frame> plain;
  for (const SimFrame& f : frames) plain.push_back(f.frame);
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

// The batch path of `config` on one merged cloud: boxes, what was segmented, statistics, time.
void segment(const Cloud& cloud, const SensorComparisonConfig& config, SensorComparisonRow& row) {
  if (config.cell) {
    const CloudBoxes result = boxes_of_cloud(cloud, *config.cell);
    row.points_used = result.voxels;
    row.seconds = result.seconds;
    row.boxes = result.boxes;
    row.summary = summary(result);
    return;
  }
  const Cloud used = downsampled(cloud, config.voxel);
  row.points_used = used.size();
  const auto start = std::chrono::steady_clock::now();
  const SegmentResult result = segment_cloud(used, config.segment);
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  row.boxes = result.boxes;
  row.summary = summary(result.stats);
}

std::string percent(double share) {
  return research::fixed(100.0 * share, 1) + " %";
}

using Measure = std::function<double(const SensorComparisonRow&)>;

// One bar chart from `low` to `high` (shares, axis at quarter steps), bars drawn from the zero line.
void bar_panel(research::SvgPlot& svg, const std::vector<SensorComparisonRow>& rows, double x0,
               const std::string& title, const Measure& value) {
  const double panel_w = 240, panel_h = 220, top = 40, bar_w = 44, gap = 28;
  const char* colours[] = {"#4477aa", "#ee6677", "#228833", "#ccbb44", "#66ccee"};
  double low = 0, high = 0.1;
  for (const SensorComparisonRow& r : rows) low = std::min(low, value(r)), high = std::max(high, value(r));
  low = std::floor(low * 4) / 4, high = std::ceil(high * 4) / 4;
  const research::PlotAxis y{high, low, top, top + panel_h};
  svg.text(x0 + panel_w / 2, 20, title, "middle", 13);
  svg.y_grid(y, low, high, high - low <= 2.0 ? 0.25 : 0.5, x0, x0 + panel_w, percent, "#ddd", "#ddd");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double v = value(rows[i]);
    const double x = x0 + gap + static_cast<double>(i) * (bar_w + gap);
    const double y0 = y(std::max(v, 0.0)), y1 = y(std::min(v, 0.0));
    svg.rect(x, y0, bar_w, y1 - y0, colours[i % 5]);
    svg.text(x + bar_w / 2, v >= 0 ? y0 - 4 : y1 + 14, percent(v), "middle");
    svg.text(x + bar_w / 2, top + panel_h + 16, rows[i].model, "middle", 10);
  }
  svg.line(x0, top, x0, top + panel_h, "black");
  svg.line(x0, y(0), x0 + panel_w, y(0), "black");
}

}  // namespace

std::vector<SensorComparisonRow> compare_sensors(const Scene& scene, const SensorComparisonConfig& config) {
  const Simulator noisy(scene, SimOptions{true, 2});
  const Simulator exact(without_depth_filter(scene), SimOptions{false, 2});
  std::vector<SensorComparisonRow> rows;
  for (std::size_t i = 0; i < scene.sensors.size(); ++i) {
    const int index = static_cast<int>(i);
    SensorComparisonRow row;
    row.sensor = scene.sensors[i].name;
    row.model = to_string(scene.sensors[i].model);
    const Cloud cloud = merged_cloud(noisy.sweep(index));
    row.points = cloud.size();
    segment(cloud, config, row);
    const Cloud truth = merged_cloud(exact.sweep(index));
    row.score = score_boxes(scene.obstacles, row.boxes.boxes, truth, config.region);
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string sensor_comparison_table(const std::vector<SensorComparisonRow>& rows) {
  std::ostringstream out;
  out << "| sensor | model | points (segmented) | boxes | coverage | lost free space | blocked free space | "
         "segment time |\n"
      << "|---|---|---|---|---|---|---|---|\n";
  for (const SensorComparisonRow& r : rows) {
    out << "| " << r.sensor << " | " << r.model << " | " << r.points << " (" << r.points_used << ") | "
        << r.score.boxes << " | " << percent(r.score.coverage) << " | " << percent(r.score.lost_free_space)
        << " | " << percent(r.score.blocked_free_space) << " | " << research::fixed(r.seconds, 2) << " s |\n";
  }
  return out.str();
}

std::string sensor_comparison_csv(const std::vector<SensorComparisonRow>& rows) {
  std::ostringstream out;
  out << "sensor;model;points;points_used;boxes;coverage;lost_free_space;blocked_free_space;true_volume;"
         "box_volume;segment_seconds\n";
  for (const SensorComparisonRow& r : rows) {
    out << r.sensor << ";" << r.model << ";" << r.points << ";" << r.points_used << ";" << r.score.boxes
        << ";" << r.score.coverage << ";" << r.score.lost_free_space << ";" << r.score.blocked_free_space
        << ";" << r.score.true_volume << ";" << r.score.box_volume << ";" << r.seconds << "\n";
  }
  return out.str();
}

// Coverage (higher is safer), lost free space (signed: boxes smaller than the objects give negative values)
// and blocked free space (box volume outside every object; lower leaves more workspace to the planner).
std::string sensor_comparison_svg(const std::vector<SensorComparisonRow>& rows, const std::string& caption) {
  const double panel_w = 240, panel_h = 220, left = 60, top = 40;
  research::SvgPlot svg(3 * (panel_w + left) + 20, panel_h + top + 70);
  bar_panel(svg, rows, left, "coverage of the seen surface",
            [](const SensorComparisonRow& r) { return r.score.coverage; });
  bar_panel(svg, rows, 2 * left + panel_w, "lost free space",
            [](const SensorComparisonRow& r) { return r.score.lost_free_space; });
  bar_panel(svg, rows, 3 * left + 2 * panel_w, "blocked free space",
            [](const SensorComparisonRow& r) { return r.score.blocked_free_space; });
  svg.text(left, top + panel_h + 50, caption, "start", 11);
  return svg.str();
}

}  // namespace cellmap::sim
