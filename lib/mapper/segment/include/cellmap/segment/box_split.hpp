// SPDX-License-Identifier: Apache-2.0
#pragma once
// Few, tight boxes: a segment's box is split where the parts' boxes block markedly less free space, and
// boxes are joined where their union box blocks little more. Both judge free space as the sensor saw it
// (segment/free_space.hpp), so an object's hidden inside is never counted as space saved.

#include <Eigen/Core>

#include <cstddef>

#include "cellmap/frame/cloud.hpp"
#include "cellmap/preprocess/neighbourhoods.hpp"
#include "cellmap/segment/fit.hpp"
#include "cellmap/segment/segments.hpp"

namespace cellmap {

struct BoxSplitParams final {
  BoxKind kind = BoxKind::kOriented;  ///< the boxes fitted to the parts
  double cube = 0.0;                  ///< metres: each point stands for a cube of this edge (see fit_box)
  /// A box is split in two when the two parts' boxes block at least this share of its volume less free
  /// space (0 < min_gain <= 1).
  double min_gain = 0.25;
  /// Two boxes are joined when the box of their union blocks at most this share of its own volume more free
  /// space than they do, i.e. when it is far from being split again (0 = never join; keep it below min_gain
  /// so a join never undoes a split).
  double max_growth = 0.1;
  int max_depth = 6;           ///< a segment's pieces are split again at most this many times
  double gap = 0.01;           ///< metres: points closer than this (neighbours) are connected
  double angular_step = 0.01;  ///< radians: direction bins of SeenFreeSpace (about the point spacing / range)
  double margin = 0.02;        ///< metres: thickness of a seen surface (SeenFreeSpace)
  double adjacency = 0.05;     ///< metres: only boxes whose bounds come this close are considered for joining
  int threads = 1;  ///< segments are split on up to this many threads (the result does not depend on it)
  /// @throws Error naming the field if a value is out of range.
  void validate() const;
};

/// Divides every segment's points into pieces, recursively, while the pieces' boxes block at least min_gain
/// of the box's volume less free space than the box, where free means seen free from `viewpoint` around
/// that segment's points. Tried in order: the part's connected pieces (neighbours within `gap`), then cuts
/// across its box's axes, each side falling into its connected pieces. Per axis two cuts are tried, the one
/// that minimises the two sides' summed box volume and the same with sides of at least a tenth of the points
/// (the volume heuristic of bounding-volume hierarchies: all cuts along an axis in O(n log n) from prefix and
/// suffix extents), smallest volume first. A convex object seen from several sides thus keeps one box; a
/// post on a plate, pallets merged with the table they stand on or a floor seen as strips around a table
/// are cut where that frees space. Every point keeps a segment. `neighbourhoods` are the cloud's (k-NN
/// lists, nearest first). Returns the new labels and the number of segments that were split
/// (`split_count`). @throws Error if sizes disagree or params are invalid.
[[nodiscard]] Segments split_by_free_space(const Cloud& cloud, const Neighbourhoods& neighbourhoods,
                                           const Segments& segments, const Eigen::Vector3d& viewpoint,
                                           const BoxSplitParams& params, std::size_t* split_count = nullptr);

/// Joins segments greedily, the cheapest pair first, while the box fitted to a pair's union blocks at most
/// max_growth of its volume more free space than their own two boxes (seen free around the pair's points),
/// among pairs whose boxes' bounds lie within `adjacency`: fragments and faces join their
/// object, boxes stacked flush become one. Returns the new labels and the number of joins (`join_count`).
/// @throws Error if sizes disagree or params are invalid.
[[nodiscard]] Segments join_by_free_space(const Cloud& cloud, const Segments& segments,
                                          const Eigen::Vector3d& viewpoint, const BoxSplitParams& params,
                                          std::size_t* join_count = nullptr);

}  // namespace cellmap
