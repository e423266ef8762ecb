// SPDX-License-Identifier: Apache-2.0
#pragma once
// One cloud → boxes by the cell pipeline's own stages: the batch tool's path (`cellmap segment`,
// `cellmap sensor-comparison`). The cloud becomes the occupied voxels of the map's grid, groups too small to
// be an obstacle are left out as noise, the rest is segmented into boxes holding whole voxels and every
// obstacle voxel is covered — what cellmapd's first version makes of a settled map, with the same config.

#include <cstddef>
#include <string>

#include "cellmap/boxes/box.hpp"
#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/frame/cloud.hpp"

namespace cellmap {

/// The boxes of one cloud and what became of its points. Every point not counted in `noise_points`,
/// `outside_map` or `outside_boxes` (the safety property wants 0) is inside a box; a noise point may be too.
struct CloudBoxes final {
  BoxSet boxes;                   ///< version 1, frame "cell", ids 1..n
  std::size_t points = 0;         ///< points in
  std::size_t voxels = 0;         ///< occupied voxels (`occupancy.resolution`) holding them
  std::size_t noise_voxels = 0;   ///< of those, in 26-connected groups below `change.min_voxels`: not boxed
  std::size_t noise_points = 0;   ///< points in noise voxels
  std::size_t outside_map = 0;    ///< points outside the map's key range
  std::size_t outside_boxes = 0;  ///< other points inside no box
  double seconds = 0;             ///< wall time
};

/// Runs the cell pipeline on `points_C` (metres, cell frame; `sensor_origin_` = the viewpoint normals face)
/// taken as its settled map (CellPipeline::settle_on, then resegment_everything()). Thread-safe (no shared
/// state). @throws Error as CellPipeline.
[[nodiscard]] CloudBoxes boxes_of_cloud(const Cloud& points_C, const CellPipelineConfig& config);

/// One line: points, voxels, noise, boxes, points outside every box, seconds.
[[nodiscard]] std::string summary(const CloudBoxes& result);

}  // namespace cellmap
