#pragma once
// The cell pipeline: one cell's incremental processing of sweeps, fusion → change detection → re-segmentation
// of the changed regions only → reconciliation with the current boxes. Its output is the cell's boxes, their
// id counter and the map state to persist with them; no I/O, no DDS, no threads.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/change/change_detector.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/environment/reconcile.hpp"
#include "cellmap/occupancy/occupancy_config.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap {

/// Everything the cell pipeline is configured with: four sections of a config file and the settling policy.
struct CellPipelineConfig final {
  OccupancyConfig occupancy;   ///< `occupancy` section
  ChangeConfig change;         ///< `change` section (change detection)
  SegmentConfig segment;       ///< `segment` section: the keys of config/segment.yaml
  ReconcileOptions reconcile;  ///< `reconcile` section
  /// Sweeps fused into an empty map before its first version (`change.settle_sweeps`, [0, 100000]; default
  /// 15). A fresh map keeps gaining voxels for a while (surfaces seen at grazing angles need several sweeps
  /// to collect two hits, flying pixels in unobserved space decay slowly), so the first version is one
  /// segmentation of the settled map instead of a trickle of small versions. 0 = the first sweep makes it.
  int settle_sweeps = 15;

  /// Reads the sections `occupancy`, `change` (settle_sweeps included), `segment` and `reconcile` of `root`
  /// and marks them read; absent keys keep the defaults above.
  /// @throws Error naming the key ("change.settle_sweeps: ...") for unknown keys, wrong types or bad ranges.
  [[nodiscard]] static CellPipelineConfig from_yaml(YamlMap& root);
};

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

/// Boxes re-fitted to the occupied evidence of an area and reconciled with the current boxes.
struct Resegmentation final {
  Reconciled reconciled;
  std::size_t evidence = 0;  ///< occupied voxels that were segmented
};

/// The incremental pipeline of one cell. Boxes are fitted to the centres of occupied voxels so that they hold
/// the whole voxels (`segment.voxel` is set to the map's resolution), so every sensor point that fell into an
/// occupied voxel of a re-segmented region is inside a box. Box ids are never reused: every new box gets the
/// next id of the counter. Not thread-safe; one instance per cell, driven by one thread.
class CellPipeline final {
 public:
  /// Starts from `boxes` and, if `map_state` is given, the map saved by map_state() (else an empty map, which
  /// settles first). `next_box_id` must be above every id this cell ever handed out (not only the ids in
  /// `boxes`): it is where the counter goes on. A map state written by an older version that still carries
  /// the counter raises it to that counter if higher.
  /// @throws Error if the config is invalid or the map state is unreadable.
  explicit CellPipeline(const CellPipelineConfig& config, std::vector<Box> boxes = {},
                        std::uint64_t next_box_id = 1,
                        const std::optional<std::string>& map_state = std::nullopt);

  /// Fuses `sweep`, detects confirmed changes and, if there are any, re-segments the evidence they touch
  /// (resegment()) and applies the result. A pipeline that started from an empty map first settles: it
  /// publishes nothing for `settle_sweeps` sweeps, then applies resegment_everything() once (the first
  /// version), and from then on works on changes only.
  SweepReport process(const Sweep& sweep);

  /// What process() makes of one sweep's confirmed changes, on the current state and without applying it:
  /// the occupied evidence inside the regions of `changes`, inside every current box that lost at least a
  /// tenth of its voxels, and inside every box lying wholly within that area, leaving out what the other
  /// boxes cover, segmented and reconciled with the current boxes. Const and repeatable, so one change can be
  /// evaluated on a fixed state (`cellmap bench segment` times it against resegment_everything()).
  [[nodiscard]] Resegmentation resegment(const ChangeSet& changes) const;
  /// What process() applies for the first version: the whole map segmented and reconciled with every current
  /// box in scope. Also the anchor that shows what resegment() saves.
  [[nodiscard]] Resegmentation resegment_everything() const;

  [[nodiscard]] const std::vector<Box>& boxes() const { return boxes_; }
  /// The id the next new box gets: above every id this pipeline handed out or was started with.
  [[nodiscard]] std::uint64_t next_box_id() const { return next_box_id_; }
  [[nodiscard]] const OccupancyMap& map() const { return map_; }
  /// The map and the viewpoint normals face, as one opaque string (what a restart passes back to the
  /// constructor; also how a measurement clones a pipeline). The box-id counter is not part of it: it is
  /// kept with the versions (VersionStore), so a lost map state cannot bring back an id.
  [[nodiscard]] std::string map_state() const;

 private:
  // The region of every change, and the ids of the boxes the changes take away evidence from.
  struct Scope {
    std::vector<Region> area;
    std::vector<std::uint64_t> boxes;
  };
  [[nodiscard]] Scope scope_of(const ChangeSet& changes) const;
  // Adds to `scope` the boxes lying wholly inside its area (to a voxel).
  void add_boxes_within(Scope& scope) const;
  // Boxes for the occupied voxels in `area` that no box of `kept` covers yet; `evidence` counts those voxels.
  [[nodiscard]] std::vector<Box> fit_boxes(const std::vector<Region>& area, const std::vector<Box>& kept,
                                           std::size_t& evidence) const;
  void restore(const std::string& map_state);
  void update_viewpoint(const Sweep& sweep);
  // Whether this sweep's changes (or the end of settling) call for re-segmentation.
  [[nodiscard]] bool resegmentation_due(const ChangeSet& changes);
  void apply(Resegmentation resegmentation, SweepReport& report);

  CellPipelineConfig config_;
  OccupancyMap map_;
  ChangeDetector detector_;
  std::vector<Box> boxes_;
  std::uint64_t next_box_id_;
  Eigen::Vector3d viewpoint_C_ = Eigen::Vector3d::Zero();  // where normals are oriented towards
  bool settling_ = true;    // an empty map that has not made its first version yet
  int settled_sweeps_ = 0;  // sweeps fused while settling
};

}  // namespace cellmap
