// Per-stage time of the batch pipeline on a real Kinect scene (mOSD learn3, 307k points of which 206k finite)
// against the same stage done with plain PCL, in the same run:
//   outliers         ours (kNN + two-sided test)       vs pcl::StatisticalOutlierRemoval (k = 40, u = 3)
//   features         ours (kNN, eq. 2, normals, κ)     vs pcl::NormalEstimation (k = 40)
//   region_growing   ours (Alg. 1 with the gap d_th)   vs pcl::RegionGrowing (same k, α, κ; no gap)
//   region_growing_gap  ours                           vs pcl::RegionGrowing + the gap in validatePoint
//   obb              ours (PCA + axis refinement)      vs pcl::MomentOfInertiaEstimation::getOBB
// on the segments of our own pipeline for the OBB stage. A ratio above 1 means ours is faster.
#include <benchmark/benchmark.h>
#include <pcl/features/moment_of_inertia_estimation.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/region_growing.h>

#include <cstdio>
#include <filesystem>

#include "cellmap/common/error.hpp"
#include "cellmap/io/cloud_file.hpp"
#include "cellmap/segment/pipeline.hpp"
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

constexpr int kIterations = 3;
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
       {"obb", "BM_ObbOurs/iterations:3", "BM_ObbPcl/iterations:1"}});
}
