// SPDX-License-Identifier: Apache-2.0
// Prints the per-scene table of the batch pipeline on the mOSD box scenes: points, clusters, boxes, coverage,
// volumetric and point-set IoU per object (see mosd_score.hpp) and time per stage.
// Usage: cellmap-mosd-table [DIR] [FIRST LAST] [--config FILE] [--verbose]
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "cellmap/common/error.hpp"
#include "cellmap/io/cloud_file.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "mosd_score.hpp"

namespace {

using namespace cellmap;

struct Options {
  std::string dir = std::string(CELLMAP_SHARED_DATA) + "/mosd";
  std::string config_file;
  bool verbose = false;
  int first = 0;
  int last = 24;
};

Options parse_options(int argc, char** argv) {
  Options options;
  std::vector<std::string> positional;
  for (int a = 1; a < argc; ++a) {
    if (std::strcmp(argv[a], "--verbose") == 0) {
      options.verbose = true;
    } else if (std::strcmp(argv[a], "--config") == 0 && a + 1 < argc) {
      options.config_file = argv[++a];
    } else {
      positional.emplace_back(argv[a]);
    }
  }
  if (!positional.empty()) options.dir = positional[0];
  if (positional.size() >= 3) {
    options.first = std::stoi(positional[1]);
    options.last = std::stoi(positional[2]);
  }
  return options;
}

// Every object of every scene, for the last line.
struct Totals {
  std::vector<double> iou, volume_iou;
  std::size_t points = 0, covered = 0;

  void add(const mosd::Score& s) {
    iou.insert(iou.end(), s.iou.begin(), s.iou.end());
    volume_iou.insert(volume_iou.end(), s.volume_iou.begin(), s.volume_iou.end());
    points += s.object_points;
    covered += s.covered_object_points;
  }
};

double smallest(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::min_element(values.begin(), values.end());
}

void print_header() {
  std::printf("%-8s %7s %7s %5s %7s %6s %5s %8s %8s %8s %8s %7s | %6s %6s %6s %6s %6s %6s %6s\n", "scene",
              "points", "dropped", "objs", "regions", "merged", "boxes", "coverage", "med.vIoU", "min.vIoU",
              "med.IoU", "min.IoU", "feat", "sor", "grow", "left", "merge", "split", "total");
}

void print_scene(int n, const mosd::Score& s, const SegmentStats& t) {
  std::printf(
      "learn%-3d %7zu %7zu %5zu %7zu %6zu %5zu %7.2f%% %8.3f %8.3f %8.3f %7.3f | %6.3f %6.3f %6.3f %6.3f "
      "%6.3f "
      "%6.3f %6.3f\n",
      n, t.points_in, t.dropped(), s.iou.size(), t.regions, t.merged_segments, t.boxes, 100.0 * s.coverage(),
      mosd::median(s.volume_iou), smallest(s.volume_iou), mosd::median(s.iou), smallest(s.iou), t.t_features,
      t.t_outliers, t.t_grow, t.t_leftovers, t.t_merge, t.t_split, t.t_total());
}

void print_table(const Options& options) {
  const SegmentConfig config =
      options.config_file.empty() ? SegmentConfig{} : SegmentConfig::load(options.config_file);
  print_header();
  Totals totals;
  for (int n = options.first; n <= options.last; ++n) {
    const CloudFile cloud = load_cloud_file(options.dir + "/learn" + std::to_string(n) + ".pcd");
    const SegmentResult result = segment_cloud(cloud.points, config);
    const mosd::Score s = mosd::score(cloud.points, cloud.labels, result.boxes.boxes);
    totals.add(s);
    print_scene(n, s, result.stats);
    if (options.verbose) {
      for (const std::string& line : s.detail) std::printf("    %s\n", line.c_str());
    }
    std::fflush(stdout);
  }
  std::printf("all: objects %zu, coverage %.3f%%, median volumetric IoU %.3f, median point-set IoU %.3f\n",
              totals.iou.size(), totals.points ? 100.0 * totals.covered / totals.points : 100.0,
              mosd::median(totals.volume_iou), mosd::median(totals.iou));
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse_options(argc, argv);
  if (!std::filesystem::is_directory(options.dir)) {
    std::fprintf(stderr, "mosd_table: %s is absent (the mOSD scenes live in ../shared/data/mosd)\n",
                 options.dir.c_str());
    return 1;
  }
  try {
    print_table(options);
  } catch (const Error& e) {
    std::fprintf(stderr, "mosd_table: %s\n", e.what());
    return 1;
  }
  return 0;
}
