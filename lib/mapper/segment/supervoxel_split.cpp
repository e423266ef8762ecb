// SPDX-License-Identifier: Apache-2.0
#include "cellmap/segment/supervoxel_split.hpp"

#include <pcl/segmentation/supervoxel_clustering.h>

#include <unordered_map>

#include "cellmap/common/error.hpp"
#include "cellmap/preprocess/point_search.hpp"
#include "cellmap/segment/fit.hpp"

namespace cellmap {
namespace {

// Supervoxel label (0 = none) of each point of `part`, with unlabelled points given their nearest labelled
// neighbour's label. Returns all zeros when VCCS produced no supervoxel.
std::vector<std::uint32_t> supervoxel_labels(const Cloud::Ptr& part, const SplitParams& params) {
  pcl::SupervoxelClustering<pcl::PointXYZ> vccs(static_cast<float>(params.voxel_resolution),
                                                static_cast<float>(params.seed_resolution));
  // Our clouds are in the cell frame, not organized camera images: no camera-depth transform.
  vccs.setUseSingleCameraTransform(false);
  vccs.setInputCloud(part);
  std::map<std::uint32_t, pcl::Supervoxel<pcl::PointXYZ>::Ptr> supervoxels;
  vccs.extract(supervoxels);
  std::vector<std::uint32_t> labels(part->size(), 0);
  if (supervoxels.empty()) return labels;
  const pcl::PointCloud<pcl::PointXYZL>::Ptr labelled = vccs.getLabeledCloud();
  std::vector<int> with_label;
  for (std::size_t i = 0; i < part->size(); ++i) {
    labels[i] = (*labelled)[i].label;
    if (labels[i] != 0) with_label.push_back(static_cast<int>(i));
  }
  if (with_label.empty() || with_label.size() == part->size()) return labels;
  const PointSearch tree(*part, with_label);
  pcl::Indices found(1);
  std::vector<float> found_sq(1);
  std::vector<std::uint32_t> filled = labels;
  for (std::size_t i = 0; i < part->size(); ++i) {
    if (labels[i] == 0 && tree.nearest((*part)[i], 1, found, found_sq) > 0) filled[i] = labels[found[0]];
  }
  return filled;
}

}  // namespace

Segments split_large_segments(const Cloud& cloud, const Segments& segments, const SplitParams& params,
                              std::size_t* split_count) {
  if (!(params.max_extent > 0.0) || !(params.voxel_resolution > 0.0) || !(params.seed_resolution > 0.0)) {
    throw Error("split: max_extent, voxel_resolution and seed_resolution must be > 0");
  }
  if (segments.label.size() != cloud.size()) throw Error("split: labels and cloud differ in size");
  Segments result;
  result.label.assign(cloud.size(), -1);
  std::size_t split = 0;
  for (const std::vector<int>& members : segments.members()) {
    if (members.empty()) continue;
    const Box box = fit_box(cloud, members, BoxKind::kOriented);
    bool done = false;
    if (2.0 * box.half_extents.maxCoeff() > params.max_extent && members.size() > 1) {
      auto part = std::make_shared<Cloud>();
      part->reserve(members.size());
      for (int i : members) part->push_back(cloud[i]);
      const std::vector<std::uint32_t> labels = supervoxel_labels(part, params);
      if (labels[0] != 0) {
        std::unordered_map<std::uint32_t, int> segment_of;
        for (std::size_t m = 0; m < members.size(); ++m) {
          const auto [it, inserted] = segment_of.emplace(labels[m], result.count);
          if (inserted) ++result.count;
          result.label[members[m]] = it->second;
        }
        split += segment_of.size() > 1;
        done = true;
      }
    }
    if (!done) {
      for (int i : members) result.label[i] = result.count;
      ++result.count;
    }
  }
  if (split_count) *split_count = split;
  return result;
}

}  // namespace cellmap
