// SPDX-License-Identifier: Apache-2.0
#pragma once
// The paper's batch pipeline on one cloud: crop → neighbourhoods and features (eq. 1, 2) → outlier removal →
// region growing → leftovers → convex merge → split (the paper's VCCS, or by free space) → join by free space
// → boxes.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <optional>
#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/frame/cloud.hpp"
#include "cellmap/preprocess/outlier_removal.hpp"
#include "cellmap/preprocess/workspace.hpp"
#include "cellmap/segment/box_split.hpp"
#include "cellmap/segment/convex_merge.hpp"
#include "cellmap/segment/fit.hpp"
#include "cellmap/segment/region_growing.hpp"
#include "cellmap/segment/supervoxel_split.hpp"

namespace cellmap {

/// How segments that are too big for one box are split.
enum class SplitMethod {
  kFreeSpace,    ///< "free_space": cut where the parts' boxes block markedly less free space (box_split.hpp)
  kSupervoxels,  ///< "supervoxels": the paper's VCCS supervoxels of segments longer than max_extent
  kOff,          ///< "off": one box per segment
};

/// Every parameter of the pipeline. The defaults here are the documented ones of config/segment.yaml.
struct SegmentConfig final {
  int k = 40;  ///< neighbours per point (eq. 1, 2, normals, region growing)
  OutlierMode outlier_mode = OutlierMode::kTwoSided;
  double outlier_u = 3.0;  ///< σ multiplier of the outlier test
  RegionGrowingParams region_growing;
  /// The gap d_th actually used is at least this multiple of the median mean neighbour distance (eq. 1), so
  /// that a cloud sparser than d_th assumes still connects instead of falling apart into isolated points
  /// (0 = use d_th as given). Also applies to the leftover and merge gaps.
  double gap_floor_factor = 2.0;
  int leftover_min_points = 3;  ///< smaller leftover groups are dropped (counted)
  bool merge = true;            ///< convex merging on/off
  ConvexMergeParams merge_params;
  SplitMethod split_method = SplitMethod::kSupervoxels;
  double split_min_gain = 0.25;  ///< free_space: see BoxSplitParams::min_gain
  SplitParams split;             ///< supervoxels
  double join_max_growth = 0.0;  ///< see BoxSplitParams::max_growth; 0 = no joining
  BoxKind box_kind = BoxKind::kOriented;
  /// Metres: the points are centres of voxels of this edge (0 = plain points); boxes hold the whole voxels.
  double voxel = 0.0;
  std::optional<Workspace> workspace;  ///< crop region; none = no crop
  /// Threads the neighbourhood search and the split by free space are spread over (the result does not
  /// depend on it); not a config file key: the cell pipeline gives it the occupancy map's threads.
  int threads = 1;

  /// Reads a config document (keys as in config/segment.yaml; every key optional, missing = default).
  /// @throws Error naming the key for unknown keys, wrong types and out-of-range values.
  [[nodiscard]] static SegmentConfig from_yaml(YamlMap root);
  /// Loads a config file. @throws Error naming the file and key.
  [[nodiscard]] static SegmentConfig load(const std::string& path);
};

/// Counters and timings of one run. Every input point is in exactly one of: a box, or one of the drop
/// counters (outside_workspace, outliers_sparse, outliers_dense, isolated).
struct SegmentStats final {
  std::size_t points_in = 0;
  std::size_t outside_workspace = 0;
  std::size_t outliers_sparse = 0;  ///< mean neighbour distance above μ + u·σ
  std::size_t outliers_dense = 0;   ///< below μ − u·σ (two-sided mode)
  double gap = 0.0;                 ///< d_th used (metres), see SegmentConfig::gap_floor_factor
  std::size_t regions = 0;          ///< segments after region growing (of at least min_cluster_size)
  LeftoverStats leftovers;
  MergeStats merge;
  std::size_t merged_segments = 0;  ///< segments after merging
  std::size_t split_segments = 0;   ///< segments that were split
  std::size_t joins = 0;            ///< pairs of parts joined into one box
  std::size_t boxes = 0;
  /// Seconds per stage.
  double t_crop = 0, t_outliers = 0, t_features = 0, t_grow = 0, t_leftovers = 0, t_merge = 0, t_split = 0,
         t_join = 0, t_boxes = 0;
  [[nodiscard]] double t_total() const {
    return t_crop + t_outliers + t_features + t_grow + t_leftovers + t_merge + t_split + t_join + t_boxes;
  }
  [[nodiscard]] std::size_t dropped() const {
    return outside_workspace + outliers_sparse + outliers_dense + leftovers.isolated;
  }
};

struct SegmentResult final {
  BoxSet boxes;  ///< version 1, frame "cell", ids 1..n
  /// For each input point: the index into boxes.boxes of the box fitted to it, or -1 if it was dropped.
  std::vector<int> box_of_point;
  SegmentStats stats;
};

/// Runs the pipeline on finite points (e.g. from load_cloud_file); normals are oriented toward
/// `points.sensor_origin_`. Every point fitted to a box lies inside it. Thread-safe (no shared state).
/// @throws Error if a point is not finite or the config is invalid.
[[nodiscard]] SegmentResult segment_cloud(const Cloud& points, const SegmentConfig& config);

/// One line: points in, drops per rule, segments per step, boxes, time per stage.
[[nodiscard]] std::string summary(const SegmentStats& stats);

}  // namespace cellmap
