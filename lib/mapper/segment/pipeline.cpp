// SPDX-License-Identifier: Apache-2.0
// Equation and algorithm numbers are those of K. Zauner, J. El Dib, H. Gattringer, A. Müller,
// "Workspace Registration and Collision Detection for Industrial Robotics Applications", AIRoV 2024.
#include "cellmap/segment/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "cellmap/common/error.hpp"
#include "cellmap/preprocess/neighbourhoods.hpp"

namespace cellmap {
namespace {

class Stopwatch {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

Eigen::Vector3d vector3(YamlMap& map, const std::string& key) {
  const YAML::Node node = map.node(key);
  if (!node || !node.IsSequence() || node.size() != 3) map.fail(key, "must be a list of 3 numbers");
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    try {
      v[i] = node[i].as<double>();
    } catch (const YAML::Exception&) {
      map.fail(key, "must be a list of 3 numbers");
    }
    if (!std::isfinite(v[i]) || std::abs(v[i]) > 1e6) map.fail(key, "values must be finite metres");
  }
  return v;
}

Cloud subset(const Cloud& cloud, const std::vector<int>& indices) {
  Cloud out;
  out.reserve(indices.size());
  for (int i : indices) out.push_back(cloud[i]);
  out.sensor_origin_ = cloud.sensor_origin_;
  out.sensor_orientation_ = cloud.sensor_orientation_;
  return out;
}

// Free space is judged in direction bins one point spacing (the median distance to the nearest neighbour)
// wide at the points' median range from the viewpoint; a surface is a spacing (or half a voxel) thick.
BoxSplitParams box_split_params(const SegmentConfig& config, const Cloud& cloud, const Neighbourhoods& nb,
                                const Eigen::Vector3d& viewpoint, double gap) {
  BoxSplitParams p;
  p.kind = config.box_kind;
  p.cube = config.voxel;
  p.min_gain = config.split_min_gain;
  p.max_growth = config.join_max_growth;
  p.gap = gap;
  std::vector<double> range, spacing;
  range.reserve(cloud.size());
  for (int i = 0; i < nb.size(); ++i) {
    range.push_back((cloud[i].getVector3fMap().cast<double>() - viewpoint).norm());
    if (nb.k > 0 && nb.neighbour(i, 0) >= 0) spacing.push_back(std::sqrt(nb.sq_distance(i, 0)));
  }
  const auto median = [](std::vector<double>& v, double fallback) {
    if (v.empty()) return fallback;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  const double step = std::max(median(spacing, gap), 1e-4);
  p.angular_step = step / std::max(median(range, 1.0), 10 * step);
  p.margin = std::max(step, 0.5 * config.voxel);
  p.adjacency = std::max(gap, config.voxel);
  p.threads = config.threads;
  return p;
}

const char* split_method_name(SplitMethod method) {
  switch (method) {
    case SplitMethod::kFreeSpace:
      return "free_space";
    case SplitMethod::kOff:
      return "off";
    case SplitMethod::kSupervoxels:
      break;
  }
  return "supervoxels";
}

// The indices of the points inside the configured workspace (all without one).
std::vector<int> workspace_index(const Cloud& points, const SegmentConfig& config) {
  if (config.workspace) return crop_to_workspace(points, *config.workspace);
  std::vector<int> index(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) index[i] = static_cast<int>(i);
  return index;
}

// The region-growing gap widened to gap_floor_factor × the median neighbour distance where the cloud is
// sparser than the configured gap assumes.
double widened_gap(const SegmentConfig& config, const Neighbourhoods& nb) {
  if (nb.size() == 0) return config.region_growing.gap;
  std::vector<float> d = nb.mean_distance;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return std::max(config.region_growing.gap, config.gap_floor_factor * d[d.size() / 2]);
}

// One box per non-empty segment, ids 1, 2, ... in segment order; `index` maps cloud points to the input's.
void fit_boxes(const Cloud& cloud, const Segments& segments, const std::vector<int>& index,
               const SegmentConfig& config, SegmentResult& result) {
  for (const std::vector<int>& members : segments.members()) {
    if (members.empty()) continue;
    Box box = fit_box(cloud, members, config.box_kind, config.voxel);
    box.id = result.boxes.boxes.size() + 1;
    for (int i : members) result.box_of_point[index[i]] = static_cast<int>(result.boxes.boxes.size());
    result.boxes.boxes.push_back(box);
  }
}

// The readers of SegmentConfig::from_yaml's sections: each reads its keys into `c` and refuses any other.
void read_neighbours(YamlMap m, SegmentConfig& c) {
  c.k = static_cast<int>(m.integer("k", c.k, 3, 200));
  m.expect_all_read();
}

void read_outliers(YamlMap m, SegmentConfig& c) {
  const std::string mode = m.get<std::string>("mode", "two_sided");
  if (mode == "two_sided") {
    c.outlier_mode = OutlierMode::kTwoSided;
  } else if (mode == "one_sided") {
    c.outlier_mode = OutlierMode::kOneSided;
  } else if (mode == "off") {
    c.outlier_mode = OutlierMode::kOff;
  } else {
    m.fail("mode", "must be two_sided, one_sided or off, got '" + mode + "'");
  }
  c.outlier_u = m.number("u", c.outlier_u, 0.0, 100.0);
  m.expect_all_read();
}

void read_region_growing(YamlMap m, SegmentConfig& c) {
  RegionGrowingParams& r = c.region_growing;
  r.gap = m.number("gap", r.gap, 1e-4, 1.0);
  r.max_curvature = m.number("max_curvature", r.max_curvature, 0.0, 1.0 / 3.0);
  r.max_angle = m.number("max_angle", r.max_angle, 0.0, M_PI);
  r.min_cluster_size = static_cast<int>(m.integer("min_cluster_size", r.min_cluster_size, 1, 100000000));
  c.gap_floor_factor = m.number("gap_floor_factor", c.gap_floor_factor, 0.0, 100.0);
  m.expect_all_read();
}

void read_leftovers(YamlMap m, SegmentConfig& c) {
  c.leftover_min_points = static_cast<int>(m.integer("min_points", c.leftover_min_points, 1, 1000000));
  m.expect_all_read();
}

void read_merge(YamlMap m, SegmentConfig& c) {
  ConvexMergeParams& p = c.merge_params;
  c.merge = m.get<bool>("enabled", c.merge);
  p.patch_radius = m.number("patch_radius", p.patch_radius, 1e-4, 1.0);
  p.concavity_tolerance = m.number("concavity_tolerance", p.concavity_tolerance, 0.0, M_PI);
  p.min_boundary_points =
      static_cast<int>(m.integer("min_boundary_points", p.min_boundary_points, 1, 1000000));
  p.samples_per_boundary =
      static_cast<int>(m.integer("samples_per_boundary", p.samples_per_boundary, 1, 100000));
  m.expect_all_read();
}

void read_split(YamlMap m, SegmentConfig& c) {
  const std::string method = m.get<std::string>("method", split_method_name(c.split_method));
  if (method == "free_space") {
    c.split_method = SplitMethod::kFreeSpace;
  } else if (method == "supervoxels") {
    c.split_method = SplitMethod::kSupervoxels;
  } else if (method == "off") {
    c.split_method = SplitMethod::kOff;
  } else {
    m.fail("method", "must be free_space, supervoxels or off, got '" + method + "'");
  }
  c.split_min_gain = m.number("min_gain", c.split_min_gain, 1e-3, 1.0);
  SplitParams& s = c.split;
  s.max_extent = m.number("max_extent", s.max_extent, 1e-3, 1e3);
  s.voxel_resolution = m.number("voxel_resolution", s.voxel_resolution, 1e-4, 1.0);
  s.seed_resolution = m.number("seed_resolution", s.seed_resolution, 1e-3, 10.0);
  if (s.seed_resolution < s.voxel_resolution) m.fail("seed_resolution", "must be >= voxel_resolution");
  m.expect_all_read();
}

void read_join(YamlMap m, SegmentConfig& c) {
  c.join_max_growth = m.number("max_growth", c.join_max_growth, 0.0, 0.99);
  if (c.join_max_growth >= c.split_min_gain && c.split_method == SplitMethod::kFreeSpace) {
    m.fail("max_growth", "must be below split.min_gain (a join must not undo a split)");
  }
  m.expect_all_read();
}

void read_boxes(YamlMap m, SegmentConfig& c) {
  const std::string kind = m.get<std::string>("kind", to_string(c.box_kind));
  c.box_kind = box_kind_from_string(kind, (m.source().empty() ? "" : m.source() + ": ") + m.key_path("kind"));
  c.voxel = m.number("voxel", c.voxel, 0.0, 1.0);
  m.expect_all_read();
}

void read_workspace(YamlMap m, SegmentConfig& c) {
  const Eigen::Vector3d lower = vector3(m, "lower");
  const Eigen::Vector3d upper = vector3(m, "upper");
  const double envelope = m.number("envelope", 0.0, 0.0, 100.0);
  if ((lower.array() > upper.array()).any()) m.fail("upper", "must be >= lower on every axis");
  c.workspace = Workspace::box(lower.array() - envelope, upper.array() + envelope);
  m.expect_all_read();
}

}  // namespace

SegmentConfig SegmentConfig::from_yaml(YamlMap root) {
  SegmentConfig c;
  read_neighbours(root.child("neighbours"), c);
  read_outliers(root.child("outliers"), c);
  read_region_growing(root.child("region_growing"), c);
  read_leftovers(root.child("leftovers"), c);
  read_merge(root.child("merge"), c);
  read_split(root.child("split"), c);
  read_join(root.child("join"), c);  // after split: checked against split.min_gain
  read_boxes(root.child("boxes"), c);
  if (root.has("workspace")) read_workspace(root.child("workspace"), c);
  c.merge_params.gap = c.region_growing.gap;
  root.expect_all_read();
  return c;
}

SegmentConfig SegmentConfig::load(const std::string& path) {
  return from_yaml(YamlMap::load(path));
}

namespace {

// The points the segmentation works on: cropped to the workspace, outliers removed, with their
// neighbourhoods; `index` maps them back to the input.
struct Prepared {
  std::vector<int> index;
  Cloud cloud;
  Neighbourhoods nb;
};

Prepared prepare(const Cloud& points, const SegmentConfig& config, SegmentStats& stats, Stopwatch& clock) {
  std::vector<int> index = workspace_index(points, config);
  stats.outside_workspace = points.size() - index.size();
  Cloud cropped = subset(points, index);
  stats.t_crop = clock.lap();

  // One kd-tree search serves both outlier removal (eq. 1) and the features (eq. 2) of the survivors; their
  // normals thus include the removed points' few contributions (sparse outliers are rarely anyone's
  // neighbour).
  const Neighbourhoods all =
      compute_neighbourhoods(cropped, config.k, true, points.sensor_origin_.head<3>(), config.threads);
  stats.t_features = clock.lap();
  const OutlierResult outliers = remove_outliers(all, config.outlier_u, config.outlier_mode);
  stats.outliers_sparse = outliers.removed_sparse;
  stats.outliers_dense = outliers.removed_dense;
  Prepared prepared{std::vector<int>(outliers.kept.size()), subset(cropped, outliers.kept),
                    subset_neighbourhoods(all, outliers.kept)};
  for (std::size_t i = 0; i < outliers.kept.size(); ++i) prepared.index[i] = index[outliers.kept[i]];
  stats.t_outliers = clock.lap();
  return prepared;
}

// Regions grown (Algorithm 1), the leftovers covered and convex neighbours merged; `gap` is the gap used.
Segments grow_and_merge(const Prepared& in, const SegmentConfig& config, SegmentStats& stats,
                        Stopwatch& clock, double& gap) {
  RegionGrowingParams growing = config.region_growing;
  ConvexMergeParams merging = config.merge_params;
  if (config.gap_floor_factor > 0.0) {
    growing.gap = widened_gap(config, in.nb);
    merging.gap = std::max(merging.gap, growing.gap);
  }
  gap = stats.gap = growing.gap;
  Segments segments = grow_regions(in.nb, growing);
  stats.regions = static_cast<std::size_t>(segments.count);
  stats.t_grow = clock.lap();

  stats.leftovers = cover_leftovers(in.cloud, in.nb, segments, growing.gap, config.leftover_min_points);
  stats.t_leftovers = clock.lap();

  if (config.merge) segments = merge_convex(in.cloud, in.nb, segments, merging, &stats.merge);
  stats.merged_segments = static_cast<std::size_t>(segments.count);
  stats.t_merge = clock.lap();
  return segments;
}

// Segments too big for one box split (by free space or supervoxels), then neighbours joined where one box
// holds both without blocking free space.
Segments split_and_join(const Prepared& in, Segments segments, const SegmentConfig& config,
                        const Eigen::Vector3d& viewpoint, double gap, SegmentStats& stats, Stopwatch& clock) {
  const BoxSplitParams parts = box_split_params(config, in.cloud, in.nb, viewpoint, gap);
  if (config.split_method == SplitMethod::kFreeSpace) {
    segments = split_by_free_space(in.cloud, in.nb, segments, viewpoint, parts, &stats.split_segments);
  } else if (config.split_method == SplitMethod::kSupervoxels) {
    segments = split_large_segments(in.cloud, segments, config.split, &stats.split_segments);
  }
  stats.t_split = clock.lap();
  if (config.join_max_growth > 0)
    segments = join_by_free_space(in.cloud, segments, viewpoint, parts, &stats.joins);
  stats.t_join = clock.lap();
  return segments;
}

}  // namespace

SegmentResult segment_cloud(const Cloud& points, const SegmentConfig& config) {
  SegmentResult result;
  SegmentStats& stats = result.stats;
  stats.points_in = points.size();
  result.box_of_point.assign(points.size(), -1);
  result.boxes.version = 1;
  result.boxes.frame = "cell";
  Stopwatch clock;
  const Prepared prepared = prepare(points, config, stats, clock);
  double gap = 0;
  Segments segments = grow_and_merge(prepared, config, stats, clock, gap);
  const Eigen::Vector3d viewpoint = points.sensor_origin_.head<3>().cast<double>();
  segments = split_and_join(prepared, std::move(segments), config, viewpoint, gap, stats, clock);
  fit_boxes(prepared.cloud, segments, prepared.index, config, result);
  stats.boxes = result.boxes.boxes.size();
  stats.t_boxes = clock.lap();
  return result;
}

std::string summary(const SegmentStats& s) {
  char line[512];
  std::snprintf(line, sizeof line,
                "points %zu, dropped: outside workspace %zu, outliers sparse %zu dense %zu, isolated %zu; "
                "gap %.4f m, regions %zu, leftovers attached %zu own segments %zu, merged to %zu, split %zu, "
                "joined %zu; boxes %zu; "
                "time %.3f s (features %.3f, outliers %.3f, grow %.3f, merge %.3f, split %.3f, join %.3f, "
                "boxes %.3f)",
                s.points_in, s.outside_workspace, s.outliers_sparse, s.outliers_dense, s.leftovers.isolated,
                s.gap, s.regions, s.leftovers.attached, s.leftovers.own_segments, s.merged_segments,
                s.split_segments, s.joins, s.boxes, s.t_total(), s.t_features, s.t_outliers, s.t_grow,
                s.t_merge, s.t_split, s.t_join, s.t_boxes);
  return line;
}

}  // namespace cellmap
