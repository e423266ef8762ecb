// SPDX-License-Identifier: Apache-2.0
// The boxes of cellmapd's first version on the default simulated cell, scored by volume against the scene's
// true solids; scripts/box_tradeoff runs it over a grid of `segment` settings.
//
//   cellmap-box-study [--out DIR] [--exact] [--config FILE] [--boxes FILE] [--cloud FILE] [--inject]
//                     [--sweeps N] [--max-depth-jump X]
//
// The default cell (config/cell.yaml) is swept by its Kinect (noise on unless --exact) into cellmapd's
// pipeline with its built-in defaults (or --config laid over them) until the first version. Printed: boxes,
// coverage of the seen surface, blocked free space, volume coverage and per-object volumetric IoU, over the
// region above the table and over the whole cell. --boxes scores a boxes file (e.g. a version cellmapd saved)
// instead; --cloud writes the settled map's occupied voxel centres (PCD, to study the segmentation alone);
// --inject then puts the README's example box on the table and takes it away, printing every version;
// --sweeps then runs N more sweeps of the unchanged cell, printing every 10 the occupied voxels outside every
// box (all, and those of groups of at least change.min_voxels) and the versions. --max-depth-jump sets the
// Kinect's flying-pixel filter (0 = off). Coverage is scored against the exact sweep without that filter.
// With --out: first_version.json and default_cell_boxes.svg (the boxes over the true obstacles, seen from
// above and from the front).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>

#include "box_picture.hpp"
#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/research/evaluate.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/recording.hpp"
#include "cellmap/sim/simulator.hpp"
#include "daemon_config.hpp"

namespace cellmap {
namespace {

struct Options {
  std::string out;
  std::string boxes;  // score this boxes file instead of running the pipeline
  std::string
      cloud;  // write the settled map's occupied voxel centres here (PCD, viewpoint = mean sensor origin)
  std::string config;  // cellmapd config laid over the built-in defaults
  bool exact = false;
  bool inject = false;                   // then trace the README's inject example through the pipeline
  int sweeps = 0;                        // then run this many sweeps of the unchanged cell
  std::optional<double> max_depth_jump;  // the Kinect's, instead of the scene's
};

Cloud sweep_cloud(const std::vector<sim::SimFrame>& frames) {
  std::vector<Frame> plain;
  for (const sim::SimFrame& f : frames) plain.push_back(f.frame);
  return merge_frames(plain).merged();
}

void print_score(const char* what, const sim::BoxScore& s) {
  std::printf(
      "%s: %zu boxes, coverage %.3f %%, blocked free space %.1f %% of %.3f m3, volume coverage %.1f %%, "
      "median IoU %.3f\n",
      what, s.boxes, 100 * s.coverage, 100 * s.blocked_free_space, s.true_volume, 100 * s.volume_coverage,
      s.median_iou());
}

// cellmapd's pipeline configuration: its built-in defaults, or `config` laid over them.
CellPipelineConfig pipeline_config(const std::string& config) {
  return config.empty()
             ? daemon::DaemonConfig::parse(daemon::default_config_yaml(), "cellmapd defaults", ".").pipeline
             : daemon::DaemonConfig::load(config).pipeline;
}

// cellmapd's pipeline fed with the default cell's Kinect sweeps.
class Daemon {
 public:
  Daemon(const sim::Scene& scene, bool noise, const std::string& config)
      : simulator_(scene, sim::SimOptions{noise, 2}),
        sensor_(scene.find_sensor("kinect")),
        config_(pipeline_config(config)),
        pipeline_(config_, {}, 1) {}

  // One sweep; returns its report.
  SweepReport sweep() {
    std::vector<Frame> frames;
    for (sim::SimFrame& f : simulator_.sweep(sensor_, index_++)) frames.push_back(std::move(f.frame));
    last_ = merge_frames(frames);
    return pipeline_.process(last_);
  }

  // Sweeps until the first version.
  void settle() {
    while (index_ < 100) {
      const SweepReport report = sweep();
      if (report.change) {
        std::printf("first version after %llu sweeps: %zu boxes, segmented in %.3f s\n",
                    static_cast<unsigned long long>(index_), pipeline_.boxes().size(), report.t_segment);
        return;
      }
    }
    throw Error("no first version within 100 sweeps");
  }

  // Applies `edit` and prints every version of the next `sweeps` sweeps; returns how many there were.
  int trace(const transport::SceneEdit& edit, int sweeps) {
    simulator_.apply(edit);
    int versions = 0;
    for (int n = 1; n <= sweeps; ++n) {
      const SweepReport report = sweep();
      if (!report.change) continue;
      ++versions;
      std::printf("  sweep %d: +%zu ~%zu -%zu boxes (%zu in all)\n", n, report.change->added.size(),
                  report.change->modified.size(), report.change->removed.size(), pipeline_.boxes().size());
    }
    return versions;
  }

  // The settled map's occupied voxel centres, viewpoint = the last sweep's mean sensor origin.
  [[nodiscard]] Cloud voxel_centres() const {
    Cloud centres;
    for (const auto& key : pipeline_.map().occupied_keys()) {
      const Eigen::Vector3d c = pipeline_.map().centre(key);
      centres.push_back(pcl::PointXYZ(c.x(), c.y(), c.z()));
    }
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    for (const Scan& scan : last_.scans) origin += scan.origin_C / static_cast<double>(last_.scans.size());
    centres.sensor_origin_ = Eigen::Vector4f(origin.x(), origin.y(), origin.z(), 0.0f);
    return centres;
  }

  // Sweeps the unchanged cell `sweeps` times, printing every 10 sweeps what noise left outside every box.
  void watch(int sweeps) {
    std::printf("%d sweeps of the unchanged cell:\n", sweeps);
    const int min_voxels = config_.change.min_voxels;
    int versions = 0;
    for (int n = 1; n <= sweeps; ++n) {
      versions += sweep().change ? 1 : 0;
      if (n % 10 != 0 && n != sweeps) continue;
      std::printf(
          "  sweep %d: %zu occupied voxels outside every box, %zu in groups of >= %d; %d versions, %zu "
          "boxes\n",
          n, pipeline_.voxels_outside_boxes(1), pipeline_.voxels_outside_boxes(min_voxels), min_voxels,
          versions, pipeline_.boxes().size());
    }
  }

  [[nodiscard]] const std::vector<Box>& boxes() const { return pipeline_.boxes(); }

 private:
  sim::Simulator simulator_;
  int sensor_;
  CellPipelineConfig config_;
  CellPipeline pipeline_;
  std::uint64_t index_ = 0;
  Sweep last_;
};

// The README's example: a 0.2 × 0.2 × 0.3 m box put on the table, then taken away.
void trace_inject(Daemon& daemon) {
  std::printf("inject add-box --center 2.12,0.45,0.9 --half-extents 0.1,0.1,0.15, 20 sweeps:\n");
  const int added = daemon.trace(transport::SceneEdit::add_box("injected", Eigen::Vector3d(2.12, 0.45, 0.9),
                                                               Eigen::Vector3d(0.1, 0.1, 0.15)),
                                 20);
  std::printf("inject remove, 20 sweeps:\n");
  const int removed = daemon.trace(transport::SceneEdit::remove("injected"), 20);
  std::printf("versions: %d for the add, %d for the removal\n", added, removed);
}

int run(const Options& options) {
  sim::Scene scene = sim::default_scene();
  const int sensor = scene.find_sensor("kinect");
  if (options.max_depth_jump) scene.sensors[sensor].intrinsics.max_depth_jump = *options.max_depth_jump;
  const sim::Simulator exact(sim::without_depth_filter(scene), sim::SimOptions{false, 2});
  Daemon daemon(scene, !options.exact, options.config);
  std::vector<Box> boxes;
  if (options.boxes.empty()) {
    daemon.settle();
    boxes = daemon.boxes();
    if (!options.cloud.empty()) sim::write_pcd(options.cloud, daemon.voxel_centres());
  } else {
    boxes = read_box_file(options.boxes).boxes;
  }
  const Cloud surface = sweep_cloud(exact.sweep(sensor, 0));
  const Region above_table{Eigen::Vector3d(0, 0, 0.76), Eigen::Vector3d(3, 2, 2)};
  const sim::BoxScore table = sim::score_boxes(scene.obstacles, boxes, surface, above_table);
  const sim::BoxScore cell = sim::score_boxes(scene.obstacles, boxes, surface, scene.cell);
  print_score("above the table", table);
  print_score("whole cell", cell);
  for (const sim::ObjectScore& o : cell.objects) {
    std::printf("  %-14s IoU %.3f (box %llu)\n", o.name.c_str(), o.iou,
                static_cast<unsigned long long>(o.box));
  }
  if (!options.out.empty()) {
    const std::filesystem::path dir(options.out);
    std::filesystem::create_directories(dir);
    BoxSet set;
    set.version = 1;
    set.boxes = boxes;
    write_box_file(dir / "first_version.json", set);
    write_file_atomically(dir / "default_cell_boxes.svg", bench::box_picture(scene, boxes));
  }
  if (options.inject && options.boxes.empty()) trace_inject(daemon);
  if (options.sweeps > 0 && options.boxes.empty()) daemon.watch(options.sweeps);
  return 0;
}

}  // namespace
}  // namespace cellmap

int main(int argc, char** argv) {
  cellmap::Options options;
  for (int a = 1; a < argc; ++a) {
    if (std::strcmp(argv[a], "--out") == 0 && a + 1 < argc) {
      options.out = argv[++a];
    } else if (std::strcmp(argv[a], "--boxes") == 0 && a + 1 < argc) {
      options.boxes = argv[++a];
    } else if (std::strcmp(argv[a], "--cloud") == 0 && a + 1 < argc) {
      options.cloud = argv[++a];
    } else if (std::strcmp(argv[a], "--config") == 0 && a + 1 < argc) {
      options.config = argv[++a];
    } else if (std::strcmp(argv[a], "--inject") == 0) {
      options.inject = true;
    } else if (std::strcmp(argv[a], "--exact") == 0) {
      options.exact = true;
    } else if (std::strcmp(argv[a], "--sweeps") == 0 && a + 1 < argc) {
      options.sweeps = std::atoi(argv[++a]);
    } else if (std::strcmp(argv[a], "--max-depth-jump") == 0 && a + 1 < argc) {
      options.max_depth_jump = std::atof(argv[++a]);
    } else {
      std::fprintf(stderr,
                   "usage: cellmap-box-study [--out DIR] [--exact] [--config FILE] [--boxes FILE] [--cloud "
                   "FILE] [--inject] [--sweeps N] [--max-depth-jump X]\n");
      return 2;
    }
  }
  try {
    return cellmap::run(options);
  } catch (const cellmap::Error& e) {
    std::fprintf(stderr, "box_study: %s\n", e.what());
    return 1;
  }
}
