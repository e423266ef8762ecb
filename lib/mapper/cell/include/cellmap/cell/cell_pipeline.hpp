#pragma once
// One cell's processing of a sweep: fusion → change detection → re-segmentation of the changed regions only
// → reconciliation with the current boxes. No I/O, no DDS: the daemon's main loop versions, persists and
// publishes what this returns.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/change/change_detector.hpp"
#include "cellmap/environment/reconcile.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "cellmap/sweep/sweep.hpp"
#include "daemon_config.hpp"

namespace cellmap::daemon {

/// What one sweep did, for the log line and the status topic.
struct SweepReport final {
  std::size_t points = 0;                          ///< points in the sweep
  std::size_t hit_voxels = 0;                      ///< voxels that got a hit
  std::size_t free_voxels = 0;                     ///< voxels that got free-space evidence
  std::size_t flipped = 0;                         ///< voxels whose occupied/free state flipped in this sweep
  std::size_t regions = 0;                         ///< confirmed change regions
  std::size_t evidence = 0;                        ///< occupied voxels re-segmented
  std::size_t boxes = 0;                           ///< boxes after the sweep
  double t_fuse = 0, t_change = 0, t_segment = 0;  ///< seconds
  ChangeSet changes;                               ///< the change regions confirmed in this sweep
  std::optional<Reconciled> change;                ///< set when the boxes changed (a new version is due)
};

/// The incremental pipeline of one cell. Boxes are fitted to the centres of occupied voxels and then grown by
/// the voxel's extent along each box axis, so every sensor point that fell into an occupied voxel of a
/// re-segmented region is inside a box. Not thread-safe; one instance per cell, driven by one thread.
class CellPipeline final {
 public:
  /// Starts from `boxes` (ids below `next_box_id`) and, if `map_state` is given, the map saved by
  /// map_state() (else an empty map). @throws Error if the config is invalid or the map state is unreadable.
  CellPipeline(const DaemonConfig& config, std::vector<Box> boxes, std::uint64_t next_box_id,
               const std::optional<std::string>& map_state = std::nullopt);

  /// Fuses `sweep`, detects confirmed changes and, if there are any, re-segments the evidence inside the
  /// changed regions (plus every box in their scope) and reconciles it with the current boxes. A pipeline
  /// that started from an empty map first settles: it publishes nothing for `change.settle_sweeps` sweeps,
  /// then segments the whole map once (the first version), and from then on works on changes only.
  SweepReport process(const Sweep& sweep);

  /// The incremental step of process(), without applying it: re-segments the occupied evidence inside the
  /// regions of `changes`, inside every current box that lost at least a tenth of its voxels, and inside
  /// every box lying wholly within that area, leaving out what the other boxes cover, and reconciles the
  /// result with the current boxes. `evidence` (if given) receives the number
  /// of voxels re-segmented. Repeatable (used to measure it).
  [[nodiscard]] Reconciled resegment(const ChangeSet& changes, std::size_t* evidence = nullptr) const;

  /// Re-segments the whole map from scratch (what the incremental path avoids; used to measure it).
  [[nodiscard]] std::vector<Box> segment_everything(std::size_t* evidence = nullptr) const;
  /// segment_everything() reconciled with the current boxes (every box in scope): what publishing a change
  /// would cost without change regions.
  [[nodiscard]] Reconciled resegment_everything(std::size_t* evidence = nullptr) const;

  [[nodiscard]] const std::vector<Box>& boxes() const { return boxes_; }
  [[nodiscard]] std::uint64_t next_box_id() const { return next_box_id_; }
  [[nodiscard]] const OccupancyMap& map() const { return map_; }
  /// The map, the box-id counter and the viewpoint normals face as one opaque string (for VersionStore
  /// blobs; also how a measurement clones a pipeline).
  [[nodiscard]] std::string map_state() const;

 private:
  // Boxes for the occupied voxels in `area` that no box of `kept` covers yet.
  [[nodiscard]] std::vector<Box> fit_boxes(const std::vector<Region>& area, const std::vector<Box>& kept,
                                           std::size_t* evidence = nullptr) const;

  DaemonConfig config_;
  OccupancyMap map_;
  ChangeDetector detector_;
  std::vector<Box> boxes_;
  std::uint64_t next_box_id_;
  Eigen::Vector3d viewpoint_C_ = Eigen::Vector3d::Zero();  // where normals are oriented towards
  bool settling_ = true;    // an empty map that has not made its first version yet
  int settled_sweeps_ = 0;  // sweeps fused while settling
};

}  // namespace cellmap::daemon
