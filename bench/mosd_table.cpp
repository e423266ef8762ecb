// Prints the per-scene table of the batch pipeline on the mOSD box scenes: points, clusters, boxes, coverage,
// volumetric and point-set IoU per object (see mosd_score.hpp) and time per stage.
// Usage: cellmap-mosd-table [DIR] [FIRST LAST] [--config FILE] [--verbose]
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "cellmap/common/error.hpp"
#include "cellmap/io/cloud_file.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "mosd_score.hpp"

int main(int argc, char** argv) {
  std::string dir = std::string(CELLMAP_SHARED_DATA) + "/mosd";
  std::string config_file;
  bool verbose = false;
  std::vector<std::string> positional;
  for (int a = 1; a < argc; ++a) {
    if (std::strcmp(argv[a], "--verbose") == 0) {
      verbose = true;
    } else if (std::strcmp(argv[a], "--config") == 0 && a + 1 < argc) {
      config_file = argv[++a];
    } else {
      positional.emplace_back(argv[a]);
    }
  }
  int first = 0, last = 24;
  if (!positional.empty()) dir = positional[0];
  if (positional.size() >= 3) {
    first = std::stoi(positional[1]);
    last = std::stoi(positional[2]);
  }
  if (!std::filesystem::is_directory(dir)) {
    std::fprintf(stderr,
                 "mosd_table: %s is absent (the mOSD scenes live in "
                 "../shared/data/mosd)\n",
                 dir.c_str());
    return 1;
  }
  try {
    const cellmap::SegmentConfig config =
        config_file.empty() ? cellmap::SegmentConfig{} : cellmap::SegmentConfig::load(config_file);
    std::printf(
        "%-8s %7s %7s %5s %7s %6s %5s %8s %8s %8s %8s %7s | %6s %6s "
        "%6s %6s %6s %6s %6s\n",
        "scene", "points", "dropped", "objs", "regions", "merged", "boxes", "coverage", "med.vIoU",
        "min.vIoU", "med.IoU", "min.IoU", "feat", "sor", "grow", "left", "merge", "split", "total");
    std::vector<double> all_iou, all_volume_iou;
    std::size_t all_points = 0, all_covered = 0;
    for (int n = first; n <= last; ++n) {
      const std::string file = dir + "/learn" + std::to_string(n) + ".pcd";
      const cellmap::CloudFile cloud = cellmap::load_cloud_file(file);
      const cellmap::SegmentResult result = cellmap::segment_cloud(cloud.points, config);
      const cellmap::mosd::Score s = cellmap::mosd::score(cloud.points, cloud.labels, result.boxes.boxes);
      const cellmap::SegmentStats& t = result.stats;
      all_iou.insert(all_iou.end(), s.iou.begin(), s.iou.end());
      all_volume_iou.insert(all_volume_iou.end(), s.volume_iou.begin(), s.volume_iou.end());
      all_points += s.object_points;
      all_covered += s.covered_object_points;
      std::printf(
          "learn%-3d %7zu %7zu %5zu %7zu %6zu %5zu %7.2f%% %8.3f %8.3f %8.3f "
          "%7.3f | %6.3f %6.3f %6.3f %6.3f "
          "%6.3f %6.3f %6.3f\n",
          n, t.points_in, t.dropped(), s.iou.size(), t.regions, t.merged_segments, t.boxes,
          100.0 * s.coverage(), cellmap::mosd::median(s.volume_iou),
          s.volume_iou.empty() ? 0.0 : *std::min_element(s.volume_iou.begin(), s.volume_iou.end()),
          cellmap::mosd::median(s.iou), s.iou.empty() ? 0.0 : *std::min_element(s.iou.begin(), s.iou.end()),
          t.t_features, t.t_outliers, t.t_grow, t.t_leftovers, t.t_merge, t.t_split, t.t_total());
      if (verbose) {
        for (const std::string& line : s.detail) std::printf("    %s\n", line.c_str());
      }
      std::fflush(stdout);
    }
    std::printf(
        "all: objects %zu, coverage %.3f%%, median volumetric IoU %.3f, median "
        "point-set IoU %.3f\n",
        all_iou.size(), all_points ? 100.0 * all_covered / all_points : 100.0,
        cellmap::mosd::median(all_volume_iou), cellmap::mosd::median(all_iou));
  } catch (const cellmap::Error& e) {
    std::fprintf(stderr, "mosd_table: %s\n", e.what());
    return 1;
  }
  return 0;
}
