// SPDX-License-Identifier: Apache-2.0
#pragma once
// The paper's sensor comparison on a simulated cell: every sensor of the scene sweeps the same cell once, its
// merged cloud goes through the batch path (the cell pipeline's stages on the cloud's occupied voxels, or the
// paper's point pipeline on the cloud downsampled to equal density), and the boxes are scored against the
// scene's true obstacles (coverage of the surface the sensor saw, lost and blocked free space).
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/region.hpp"
#include "cellmap/research/evaluate.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "cellmap/sim/scene.hpp"

namespace cellmap::sim {

struct SensorComparisonConfig final {
  /// Set: every merged cloud goes through boxes_of_cloud with this config (cellmapd's stages: the cloud's
  /// occupied voxels at `occupancy.resolution`, noise groups dropped, every obstacle voxel boxed).
  std::optional<CellPipelineConfig> cell;
  /// Without `cell`: the paper's point pipeline with one parameter set for every sensor ...
  SegmentConfig segment;
  double voxel = 0.02;  ///< ... on the cloud downsampled to one point per voxel, metres (0: every point)
  /// Where boxes are scored (default: above the table of config/cell.yaml).
  Region region{Eigen::Vector3d(0, 0, 0.76), Eigen::Vector3d(3, 2, 2)};
};

/// One sensor's outcome.
struct SensorComparisonRow final {
  std::string sensor, model;
  std::size_t points = 0;       ///< merged sweep
  std::size_t points_used = 0;  ///< what was segmented: occupied voxels, or points after downsampling
  double seconds = 0;           ///< the batch path's wall time
  BoxSet boxes;                 ///< version 1, ids 1..n
  std::string summary;          ///< the batch path's one-line statistics
  BoxScore score;
};

/// Runs the comparison (both simulators on 2 threads); one row per scene sensor, in the scene's order.
/// @throws Error as the simulator, the pipeline and score_boxes.
[[nodiscard]] std::vector<SensorComparisonRow> compare_sensors(const Scene& scene,
                                                               const SensorComparisonConfig& config);

/// Markdown table: sensor, model, points (used), boxes, coverage, lost and blocked free space, segment time.
[[nodiscard]] std::string sensor_comparison_table(const std::vector<SensorComparisonRow>& rows);
/// CSV (`;`-separated, one header line).
[[nodiscard]] std::string sensor_comparison_csv(const std::vector<SensorComparisonRow>& rows);
/// Three bar charts side by side (coverage, lost free space, blocked free space) with `caption` below.
[[nodiscard]] std::string sensor_comparison_svg(const std::vector<SensorComparisonRow>& rows,
                                                const std::string& caption);

}  // namespace cellmap::sim
