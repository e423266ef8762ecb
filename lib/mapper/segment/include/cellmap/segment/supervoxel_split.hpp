// SPDX-License-Identifier: Apache-2.0
#pragma once
// Splitting oversized segments into VCCS supervoxels (paper fig. 3/4): one box around a very large cluster
// swallows free workspace. The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration
// and Collision Detection for Industrial Robotics Applications", AIRoV 2024.

#include "cellmap/frame/cloud.hpp"
#include "cellmap/segment/segments.hpp"

namespace cellmap {

struct SplitParams final {
  double max_extent = 0.5;         ///< metres: segments whose oriented box has a longer side are split
  double voxel_resolution = 0.01;  ///< metres: VCCS voxel edge
  double seed_resolution = 0.2;    ///< metres: VCCS seed spacing (about the size of one supervoxel)
};

/// Replaces every segment whose PCA box is longer than max_extent by its VCCS supervoxels
/// (pcl::SupervoxelClustering over that segment's points), so that one large or bent segment does not become
/// one box that swallows free space. Points VCCS leaves unlabelled join the supervoxel of their nearest
/// labelled point in the same segment, so the split loses no point. Returns the new labels and writes how
/// many segments were split to `split_count` when given. @throws Error on invalid parameters.
[[nodiscard]] Segments split_large_segments(const Cloud& cloud, const Segments& segments,
                                            const SplitParams& params, std::size_t* split_count = nullptr);

}  // namespace cellmap
