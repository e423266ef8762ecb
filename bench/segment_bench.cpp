// SPDX-License-Identifier: Apache-2.0
// Per-stage time of the batch pipeline on a real Kinect scene (mOSD learn3, 307k points of which 206k finite)
// against the same stage done with plain PCL, in the same run:
//   outliers         ours (kNN + two-sided test)       vs pcl::StatisticalOutlierRemoval (k = 40, u = 3)
//   features         ours (kNN, eq. 2, normals, κ)     vs pcl::NormalEstimation (k = 40)
//   region_growing   ours (Alg. 1 with the gap d_th)   vs pcl::RegionGrowing (same k, α, κ; no gap)
//   region_growing_gap  ours                           vs pcl::RegionGrowing + the gap in validatePoint
//   obb              ours (PCA + axis refinement)      vs pcl::MomentOfInertiaEstimation::getOBB
// on the segments of our own pipeline for the OBB stage. A ratio above 1 means ours is faster.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.
//
// And the cell pipeline (cellmap/cell/cell_pipeline.hpp, with cellmapd's defaults) on a simulated 30-object
// cell (the default cell's floor, table and legs plus 24 objects on the table, Kinect model with noise): the
// map is converged (the first version, then sweeps until 10 in a row publish nothing), one box is added in a
// free spot, and sweeps run until the pipeline publishes it. On the state of that sweep (map fused, boxes as
// before it) both ways of publishing the change are timed, and both end in the delta against the current
// environment:
//   incremental   change detection of that sweep (measured once, added to each iteration) + re-segmenting the
//                 evidence in the change regions and the touched boxes + reconcile + environment diff
//   anchor        re-segmenting every occupied voxel of the map (segment_everything) + reconcile with every
//                 box in scope + environment diff
// Fusion of the sweep is common to both and timed in neither (`cellmap bench fusion`).
#include <benchmark/benchmark.h>
#include <pcl/features/moment_of_inertia_estimation.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/region_growing.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/environment/environment.hpp"
#include "cellmap/io/cloud_file.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/simulator.hpp"
#include "daemon_config.hpp"
#include "ratio_report.hpp"

namespace cellmap {
namespace {

const std::string kScene = std::string(CELLMAP_SHARED_DATA) + "/mosd/learn3.pcd";
const SegmentConfig kConfig;

// The scene, loaded once; null when the shared data is absent.
Cloud::ConstPtr scene() {
  static const Cloud::ConstPtr cloud = [] {
    if (!std::filesystem::exists(kScene)) return Cloud::ConstPtr();
    return Cloud::ConstPtr(new Cloud(load_cloud_file(kScene).points));
  }();
  return cloud;
}

bool skip_without_data(benchmark::State& state) {
  if (scene()) return false;
  state.SkipWithError((kScene + " is absent (needs ../shared/data)").c_str());
  return true;
}

pcl::PointCloud<pcl::Normal>::Ptr pcl_normals(const Cloud::ConstPtr& cloud) {
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
  estimation.setInputCloud(cloud);
  estimation.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  estimation.setKSearch(kConfig.k);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  estimation.compute(*normals);
  return normals;
}

// pcl::RegionGrowing with the paper's neighbour gap d_th added in its per-neighbour test.
class GapRegionGrowing : public pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal> {
 public:
  explicit GapRegionGrowing(double gap) : sq_gap_(static_cast<float>(gap * gap)) {}

 protected:
  bool validatePoint(pcl::index_t seed, pcl::index_t point, pcl::index_t neighbour,
                     bool& is_a_seed) const override {
    if (((*input_)[point].getVector3fMap() - (*input_)[neighbour].getVector3fMap()).squaredNorm() > sq_gap_) {
      is_a_seed = false;
      return false;
    }
    return pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal>::validatePoint(seed, point, neighbour, is_a_seed);
  }

 private:
  float sq_gap_;
};

void run_pcl_region_growing(benchmark::State& state, pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal>& rg) {
  const auto normals = pcl_normals(scene());
  std::size_t regions = 0;
  for (auto _ : state) {
    rg.setMinClusterSize(kConfig.region_growing.min_cluster_size);
    rg.setNumberOfNeighbours(kConfig.k);
    rg.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
    rg.setInputCloud(scene());
    rg.setInputNormals(normals);
    rg.setSmoothnessThreshold(static_cast<float>(kConfig.region_growing.max_angle));
    rg.setCurvatureThreshold(static_cast<float>(kConfig.region_growing.max_curvature));
    std::vector<pcl::PointIndices> clusters;
    rg.extract(clusters);
    regions = clusters.size();
  }
  state.counters["regions"] = static_cast<double>(regions);
}

void BM_OutliersOurs(benchmark::State& state) {
  if (skip_without_data(state)) return;
  std::size_t removed = 0;
  for (auto _ : state) {
    const OutlierResult r = remove_outliers(compute_neighbourhoods(*scene(), kConfig.k, false),
                                            kConfig.outlier_u, kConfig.outlier_mode);
    removed = r.removed_dense + r.removed_sparse;
  }
  state.counters["removed"] = static_cast<double>(removed);
}

void BM_OutliersPcl(benchmark::State& state) {
  if (skip_without_data(state)) return;
  std::size_t removed = 0;
  for (auto _ : state) {
    pcl::StatisticalOutlierRemoval<pcl::PointXYZ> filter;
    filter.setInputCloud(scene());
    filter.setMeanK(kConfig.k);
    filter.setStddevMulThresh(kConfig.outlier_u);
    pcl::Indices kept;
    filter.filter(kept);
    removed = scene()->size() - kept.size();
  }
  state.counters["removed"] = static_cast<double>(removed);
}

void BM_FeaturesOurs(benchmark::State& state) {
  if (skip_without_data(state)) return;
  for (auto _ : state) benchmark::DoNotOptimize(compute_neighbourhoods(*scene(), kConfig.k, true));
}

void BM_FeaturesPcl(benchmark::State& state) {
  if (skip_without_data(state)) return;
  for (auto _ : state) benchmark::DoNotOptimize(pcl_normals(scene()));
}

void BM_RegionGrowingOurs(benchmark::State& state) {
  if (skip_without_data(state)) return;
  const Neighbourhoods nb = compute_neighbourhoods(*scene(), kConfig.k, true);
  int regions = 0;
  for (auto _ : state) regions = grow_regions(nb, kConfig.region_growing).count;
  state.counters["regions"] = regions;
}

void BM_RegionGrowingPcl(benchmark::State& state) {
  if (skip_without_data(state)) return;
  pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal> rg;
  run_pcl_region_growing(state, rg);
}

void BM_RegionGrowingPclGap(benchmark::State& state) {
  if (skip_without_data(state)) return;
  GapRegionGrowing rg(kConfig.region_growing.gap);
  run_pcl_region_growing(state, rg);
}

// The segments our pipeline fits boxes to, as index lists into the scene.
std::vector<std::vector<int>> pipeline_segments() {
  const SegmentResult result = segment_cloud(*scene(), kConfig);
  std::vector<std::vector<int>> segments(result.boxes.boxes.size());
  for (std::size_t i = 0; i < result.box_of_point.size(); ++i) {
    if (result.box_of_point[i] >= 0) segments[result.box_of_point[i]].push_back(static_cast<int>(i));
  }
  return segments;
}

void BM_ObbOurs(benchmark::State& state) {
  if (skip_without_data(state)) return;
  const auto segments = pipeline_segments();
  double volume = 0;
  for (auto _ : state) {
    volume = 0;
    for (const auto& s : segments) volume += fit_box(*scene(), s, BoxKind::kOriented).volume();
  }
  state.counters["boxes"] = static_cast<double>(segments.size());
  state.counters["volume_l"] = volume * 1000.0;
}

void BM_ObbPcl(benchmark::State& state) {
  if (skip_without_data(state)) return;
  const auto segments = pipeline_segments();
  double volume = 0;
  for (auto _ : state) {
    volume = 0;
    for (const auto& s : segments) {
      pcl::MomentOfInertiaEstimation<pcl::PointXYZ> moment;
      moment.setInputCloud(scene());
      moment.setIndices(pcl::IndicesPtr(new pcl::Indices(s.begin(), s.end())));
      moment.compute();
      pcl::PointXYZ min, max, position;
      Eigen::Matrix3f rotation;
      moment.getOBB(min, max, position, rotation);
      volume += static_cast<double>(max.x - min.x) * (max.y - min.y) * (max.z - min.z);
    }
  }
  state.counters["boxes"] = static_cast<double>(segments.size());
  state.counters["volume_l"] = volume * 1000.0;
}

void BM_PipelineOurs(benchmark::State& state) {
  if (skip_without_data(state)) return;
  for (auto _ : state) benchmark::DoNotOptimize(segment_cloud(*scene(), kConfig));
}

// ---- Incremental publishing of a one-object change ----

// The default cell's floor, table top and legs (its first six obstacles) plus 24 objects on a 5 × 5 grid on
// the table, one grid spot left free for the change: 30 obstacles.
sim::Scene thirty_object_cell() {
  sim::Scene scene = sim::default_scene();
  scene.obstacles.resize(6);
  int n = 0;
  for (int row = 0; row < 5; ++row) {
    for (int col = 0; col < 5; ++col) {
      if (row == 2 && col == 3) continue;  // the free spot at (2.1, 1.0)
      sim::Obstacle o;
      o.name = "object_" + std::to_string(n);
      const double height = 0.05 + 0.025 * (n % 7);  // half height 5..20 cm
      const double size = 0.07 + 0.01 * (n % 5);     // half width 7..11 cm
      switch (n % 4) {
        case 0:
          o.shape = sim::BoxShape{Eigen::Vector3d(size, 0.8 * size, height)};
          break;
        case 1:
          o.shape = sim::CylinderShape{size, height};
          break;
        case 2:
          o.shape = sim::SphereShape{size};
          break;
        default:
          o.shape = sim::BoxShape{Eigen::Vector3d(size, size, height)};
          break;
      }
      const double half_z = (n % 4 == 2) ? size : height;
      o.X_CO.translation() = Eigen::Vector3d(0.3 + 0.6 * col, 0.25 + 0.375 * row, 0.75 + half_z);
      if (n % 4 == 3) o.X_CO.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      scene.obstacles.push_back(o);
      ++n;
    }
  }
  scene.validate();
  return scene;
}

// The pipeline state just after the sweep that confirmed the added object, before its boxes were applied.
struct ChangeFixture {
  std::unique_ptr<CellPipeline> pipeline;  // map after the sweep, boxes before it
  ChangeSet changes;                       // what that sweep confirmed
  double t_change = 0;                     // seconds its change detection took
  Environment current;                     // the environment published before the change
  int sweeps_to_converge = 0;
  int sweeps_to_publish = 0;
  int other_versions = 0;  // versions between the edit and the one with the added object
  std::string failure;
};

const ChangeFixture& change_fixture() {
  static const ChangeFixture fixture = [] {
    ChangeFixture f;
    const CellPipelineConfig config =
        daemon::DaemonConfig::parse(daemon::default_config_yaml(), "cellmapd defaults", ".").pipeline;
    sim::Simulator simulator(thirty_object_cell());
    const int sensor = simulator.scene().find_sensor("kinect");
    std::uint64_t index = 0;
    const auto next_sweep = [&] {
      std::vector<Frame> frames;
      for (sim::SimFrame& frame : simulator.sweep(sensor, index++)) frames.push_back(std::move(frame.frame));
      return merge_frames(frames);
    };
    CellPipeline pipeline(config);
    std::uint64_t version = 0;
    for (int quiet = 0; (version == 0 || quiet < 10) && f.sweeps_to_converge < 200; ++f.sweeps_to_converge) {
      quiet = pipeline.process(next_sweep()).change ? (++version, 0) : quiet + 1;
    }
    f.current = Environment("bench", version, 0, pipeline.boxes());
    const transport::SceneEdit added = transport::SceneEdit::add_box("added", Eigen::Vector3d(2.1, 1.0, 0.87),
                                                                     Eigen::Vector3d(0.1, 0.08, 0.12));
    simulator.apply(added);
    while (f.sweeps_to_publish < 30) {
      const std::vector<Box> boxes_before = pipeline.boxes();
      const std::uint64_t next_id_before = pipeline.next_box_id();
      SweepReport report = pipeline.process(next_sweep());
      ++f.sweeps_to_publish;
      if (!report.change) continue;
      // Its top is seen first (the sides collect their hits a sweep or two later).
      const Eigen::Vector3d top = added.center + Eigen::Vector3d(0, 0, 0.11);
      const auto is_added = [&](const Box& box) { return box.contains(top); };
      if (std::none_of(report.change->added.begin(), report.change->added.end(), is_added)) {
        // A version from something else (the map still settling): it becomes the current environment.
        f.current = Environment("bench", f.current.version() + 1, 0, pipeline.boxes());
        ++f.other_versions;
        continue;
      }
      f.pipeline = std::make_unique<CellPipeline>(config, boxes_before, next_id_before, pipeline.map_state());
      f.changes = std::move(report.changes);
      f.t_change = report.t_change;
      return f;
    }
    f.failure = "the added object was never published";
    return f;
  }();
  return fixture;
}

void count_delta(benchmark::State& state, const Reconciled& r, const EnvironmentDelta& delta) {
  state.counters["boxes"] = static_cast<double>(r.boxes.size());
  state.counters["added"] = static_cast<double>(delta.added.size());
  state.counters["modified"] = static_cast<double>(delta.modified.size());
  state.counters["removed"] = static_cast<double>(delta.removed.size());
}

void BM_PublishChangeIncremental(benchmark::State& state) {
  const ChangeFixture& f = change_fixture();
  if (!f.failure.empty()) return state.SkipWithError(f.failure.c_str());
  std::size_t evidence = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const Resegmentation resegmentation = f.pipeline->resegment(f.changes);
    const Reconciled& r = resegmentation.reconciled;
    evidence = resegmentation.evidence;
    const EnvironmentDelta delta = diff(f.current, Environment("bench", f.current.version() + 1, 0, r.boxes));
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() +
                           f.t_change);
    count_delta(state, r, delta);
  }
  state.counters["voxels"] = static_cast<double>(evidence);
  state.counters["regions"] = static_cast<double>(f.changes.regions.size());
  state.counters["change_ms"] = f.t_change * 1e3;
  state.counters["sweeps_to_converge"] = f.sweeps_to_converge;
  state.counters["sweeps_to_publish"] = f.sweeps_to_publish;
  state.counters["other_versions"] = f.other_versions;
}

void BM_PublishChangeFull(benchmark::State& state) {
  const ChangeFixture& f = change_fixture();
  if (!f.failure.empty()) return state.SkipWithError(f.failure.c_str());
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const Reconciled r = f.pipeline->resegment_everything().reconciled;
    const EnvironmentDelta delta = diff(f.current, Environment("bench", f.current.version() + 1, 0, r.boxes));
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    count_delta(state, r, delta);
  }
  state.counters["voxels"] = static_cast<double>(f.pipeline->map().occupied_keys().size());
}

constexpr int kIterations = 3;
BENCHMARK(BM_PublishChangeIncremental)->Unit(benchmark::kMillisecond)->Iterations(20)->UseManualTime();
BENCHMARK(BM_PublishChangeFull)->Unit(benchmark::kMillisecond)->Iterations(3)->UseManualTime();
BENCHMARK(BM_OutliersOurs)->Unit(benchmark::kMillisecond)->Iterations(kIterations);
BENCHMARK(BM_OutliersPcl)->Unit(benchmark::kMillisecond)->Iterations(kIterations);
BENCHMARK(BM_FeaturesOurs)->Unit(benchmark::kMillisecond)->Iterations(kIterations);
BENCHMARK(BM_FeaturesPcl)->Unit(benchmark::kMillisecond)->Iterations(kIterations);
BENCHMARK(BM_RegionGrowingOurs)->Unit(benchmark::kMillisecond)->Iterations(kIterations);
BENCHMARK(BM_RegionGrowingPcl)->Unit(benchmark::kMillisecond)->Iterations(kIterations);
BENCHMARK(BM_RegionGrowingPclGap)->Unit(benchmark::kMillisecond)->Iterations(kIterations);
BENCHMARK(BM_ObbOurs)->Unit(benchmark::kMillisecond)->Iterations(kIterations);
BENCHMARK(BM_ObbPcl)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_PipelineOurs)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace cellmap

int main(int argc, char** argv) {
  return cellmap::bench::run_and_report(
      argc, argv,
      {{"outliers", "BM_OutliersOurs/iterations:3", "BM_OutliersPcl/iterations:3"},
       {"features", "BM_FeaturesOurs/iterations:3", "BM_FeaturesPcl/iterations:3"},
       {"region_growing", "BM_RegionGrowingOurs/iterations:3", "BM_RegionGrowingPcl/iterations:3"},
       {"region_growing_gap", "BM_RegionGrowingOurs/iterations:3", "BM_RegionGrowingPclGap/iterations:3"},
       {"obb", "BM_ObbOurs/iterations:3", "BM_ObbPcl/iterations:1"},
       {"incremental", "BM_PublishChangeIncremental/iterations:20/manual_time",
        "BM_PublishChangeFull/iterations:3/manual_time"}});
}
