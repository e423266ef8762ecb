// SPDX-License-Identifier: Apache-2.0
#pragma once
// The cell pipeline: one cell's incremental processing of sweeps, self filter → fusion → change detection →
// re-segmentation of the changed regions only → reconciliation with the current boxes. Its output is the
// cell's boxes, their id counter and the map state to persist with them; no I/O, no DDS, no threads.

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/cell/open_sweep.hpp"
#include "cellmap/change/change_detector.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/environment/reconcile.hpp"
#include "cellmap/occupancy/occupancy_config.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/robot/robot.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "cellmap/self_filter/self_filter.hpp"
#include "cellmap/sweep/sweep.hpp"
#include "cellmap/unknown/unknown_boxes.hpp"

namespace cellmap {

class OccupiedVoxels;

/// Everything the cell pipeline is configured with: six sections of a config file and the settling policy.
struct CellPipelineConfig final {
  OccupancyConfig occupancy;     ///< `occupancy` section
  ChangeConfig change;           ///< `change` section (change detection)
  SegmentConfig segment;         ///< `segment` section: the keys of config/segment.yaml
  ReconcileParams reconcile;     ///< `reconcile` section
  SelfFilterConfig self_filter;  ///< `self_filter` section (used once the pipeline knows the robot)
  /// `unknown` section; its workspace defaults to the bounds of `segment.workspace`.
  UnknownSpaceConfig unknown;
  /// Sweeps fused into an empty map before its first version (`change.settle_sweeps`, [0, 100000]; default
  /// 15). A fresh map keeps gaining voxels for a while (surfaces seen at grazing angles need several sweeps
  /// to collect two hits, flying pixels in unobserved space decay slowly), so the first version is one
  /// segmentation of the settled map instead of a trickle of small versions. 0 = the first sweep makes it.
  int settle_sweeps = 15;
  /// Sweeps a confirmed change waits before it is published, gathering the changes confirmed meanwhile into
  /// the same version (`change.gather_sweeps`, [0, 1000]; default 0). One change often is confirmed in parts
  /// a sweep or two apart: the sides of a new object seen at grazing angles collect their hits later than
  /// its top; the part of an object's old place that the robot hid while it carried the object away clears
  /// once the robot moved on. Each part would otherwise be a version of its own.
  int gather_sweeps = 0;
  /// Whether a change in which nothing appeared (removals only) waits `gather_sweeps` too
  /// (`change.gather_removals`; default true). A place that clears is mostly confirmed in one go once the
  /// cameras see through it, while a new object's sides come in after its top; false publishes removals at
  /// once and keeps the wait for arrivals. Keep it true where a robot hides part of an object's old place
  /// while it carries the object away.
  bool gather_removals = true;
  /// Every version holds every obstacle voxel of the map whole (`reconcile.cover_every_version`; default
  /// true). Obstacle voxels are those of 26-connected occupied groups of at least `change.min_voxels`; a
  /// smaller group touching nothing else is noise and never fitted. The first version holds every obstacle
  /// voxel either way. Later, a few voxels keep appearing outside the changed areas (surfaces seen at grazing
  /// angles filling in; flying pixels, where the cameras' filter lets them through) that change detection
  /// rightly ignores; each version also takes them up: boxes grown by at most `join.max_growth` of their
  /// volume, else small boxes of their own, so a version may also grow boxes away from its change. Off,
  /// versions change only what the change touched and may leave such voxels outside every box.
  bool cover_every_version = true;

  /// Reads the sections `occupancy`, `change` (settle_sweeps and gather_sweeps included), `segment`,
  /// `reconcile` (cover_every_version included), `self_filter` and `unknown` of `root` and marks them read;
  /// absent keys keep the defaults above.
  /// @throws Error naming the key ("change.settle_sweeps: ...") for unknown keys, wrong types or bad ranges.
  [[nodiscard]] static CellPipelineConfig from_yaml(YamlMap& root);
};

/// What one sweep did, for the log line and the status topic.
struct SweepReport final {
  std::size_t points = 0;          ///< points fused as hits
  std::size_t frames = 0;          ///< frames in the sweep
  std::size_t robot_points = 0;    ///< points the self filter found on the robot (fused as clear-only rays)
  std::size_t no_return_rays = 0;  ///< clear-only rays of pixels without a return
  double t_filter = 0;             ///< seconds the self filter took for all frames (frames to scans included)
  std::size_t hit_voxels = 0;      ///< voxels that got a hit
  std::size_t free_voxels = 0;     ///< voxels that got free-space evidence
  std::size_t flipped = 0;         ///< voxels whose occupied/free state flipped in this sweep
  std::size_t regions = 0;         ///< change regions confirmed in this sweep
  std::size_t evidence = 0;        ///< occupied voxels re-segmented
  std::size_t boxes = 0;           ///< boxes after the sweep
  /// Seconds of fusion (the voxels the frames observed, gathered as they came, and the map update at the
  /// sweep's end), of the map update alone, of change detection and of re-segmentation. Of fusion only the
  /// map update waits for the sweep's end; for a Sweep of scans fusion is all map update.
  double t_fuse = 0, t_update = 0, t_change = 0, t_segment = 0;
  /// Wall seconds gathering the frames took (GatheredSweep::t_gathering; 0 for a Sweep of scans).
  double t_gathering = 0;
  /// CPU seconds of the same stages, and of the self filter, on the threads that ran them and the helper
  /// threads they split them onto (cpu_seconds_with_helpers()): what a stage costs, which a wall time on a
  /// shared machine hides.
  double cpu_filter = 0, cpu_fuse = 0, cpu_update = 0, cpu_change = 0, cpu_segment = 0;
  ChangeSet changes;  ///< the change regions re-segmented in this sweep (gathered over gather_sweeps)
  std::optional<Reconciled> change;  ///< set when the obstacle boxes changed (a new version is due)
  UnknownChange unknown;             ///< what changed among the unknown boxes (not empty: a version is due)
  std::size_t unknown_boxes = 0;     ///< unknown boxes after the sweep
  bool unknown_covered = false;      ///< the workspace's unknown space was covered afresh (unknown_cover())
  double t_unknown = 0;              ///< seconds spent covering or shrinking unknown space
};

/// Boxes re-fitted to the occupied evidence of an area and reconciled with the current boxes.
struct Resegmentation final {
  Reconciled reconciled;
  std::size_t evidence = 0;  ///< occupied voxels that were segmented
  /// Whether the evidence was taken as one box unsegmented: one connected piece whose box blocks little more
  /// seen free space than the old boxes it grows from (or, for a new object, little in all).
  bool one_tight_box = false;
};

/// The incremental pipeline of one cell. Boxes are fitted to the centres of occupied voxels so that they hold
/// the whole voxels (`segment.voxel` is set to the map's resolution), so every sensor point that fell into an
/// occupied voxel of a re-segmented region is inside a box. Box ids are never reused: every new box gets the
/// next id of the counter. Not thread-safe; one instance per cell, driven by one thread.
class CellPipeline final {
 public:
  /// Starts from `boxes` (obstacle and unknown boxes; the unknown ones are dropped when unknown space is not
  /// tracked) and, if `map_state` is given, the map saved by map_state() with the flips that were
  /// pending then (else an empty map, which settles first). A map state of the older layout without them
  /// starts with no flip pending; one of a layout from before unknown space (or of a map whose unknown space
  /// was never covered) has its unknown space covered at the first sweep, when it is tracked. `next_box_id`
  /// must be above every id this cell ever handed out (not only the ids in `boxes`): it is where the counter
  /// goes on. A map state written by an older version that still carries the counter raises it to that
  /// counter if higher.
  /// @throws Error if the config is invalid or the map state is unreadable.
  explicit CellPipeline(const CellPipelineConfig& config, std::vector<Box> boxes = {},
                        std::uint64_t next_box_id = 1,
                        const std::optional<std::string>& map_state = std::nullopt);
  ~CellPipeline();
  CellPipeline(CellPipeline&&) noexcept;
  CellPipeline& operator=(CellPipeline&&) noexcept;

  /// Gathers the frames of `sweep` in an OpenSweep of this pipeline's (the robot cut out of every frame
  /// that comes with one, once filter_robot() was called and `self_filter.enabled`), then
  /// process(GatheredSweep&): what a caller that has the whole sweep at once does.
  /// @throws Error as OpenSweep::add.
  SweepReport process(FrameSweep sweep);
  /// Fuses a sweep whose frames an OpenSweep gathered (open_sweep(), possibly on another thread), then
  /// detects, re-segments and applies as process(Sweep) does. Empties `sweep.voxels`; its frames stay for
  /// the caller.
  SweepReport process(GatheredSweep& sweep);
  /// An OpenSweep for this pipeline's frames: its resolution and range, and its self filter once
  /// filter_robot() was called and `self_filter.enabled`. It refers to the filter: make it after
  /// filter_robot(), and let it go before the pipeline.
  [[nodiscard]] OpenSweep open_sweep() const;
  /// The robot the self filter cuts out of the frames from now on (its shapes padded once, here).
  /// @throws Error if the self-filter config is invalid.
  void filter_robot(const Robot& robot);
  /// The self filter in use, if any (its cost and triangle count for logs).
  [[nodiscard]] const SelfFilter* self_filter() const { return filter_.get(); }

  /// Fuses `sweep`, detects confirmed changes and, `gather_sweeps` sweeps after the first of them,
  /// re-segments the evidence the changes gathered meanwhile touch (resegment()) and applies the result. A
  /// pipeline that started from an empty map first settles: it publishes nothing for `settle_sweeps` sweeps,
  /// then applies resegment_everything() once (the first version), and from then on works on changes only.
  SweepReport process(const Sweep& sweep);

  /// Takes one cloud (metres, cell frame) as the settled map instead of fused sweeps: every voxel holding one
  /// of its points occupied (OccupancyMap::mark_occupied), normals facing its `sensor_origin_`, settling
  /// over. resegment_everything() then makes of it exactly what the first version makes of a settled map: the
  /// batch tool's path (cloud_boxes.hpp). @return the points outside the map's key range (skipped).
  std::size_t settle_on(const Cloud& points_C);

  /// What process() makes of one sweep's confirmed changes, on the current state and without applying it:
  /// the occupied evidence inside the regions of `changes`, inside every current box that lost at least a
  /// tenth of its voxels, and inside every box lying wholly within that area, leaving out what the other
  /// boxes cover, segmented and reconciled with the current boxes; a box that holds no obstacle voxel any
  /// more (its evidence cleared piece by piece, too little at a time to be a change) goes. A box that lost
  /// voxels with nothing appearing within change.margin of it shrinks in place instead (its rotation kept,
  /// the boxes lying within that margin taken in) when the shrunk box blocks at most segment.join.max_growth
  /// of its volume in seen free space: what a join accepts, and no split by free space could gain
  /// segment.split.min_gain on it (a 3 000-voxel slab: 1.4 ms shrunk, 23 ms re-segmented). Const and
  /// repeatable, so one change can be evaluated on a fixed state (`cellmap bench segment` times it against
  /// resegment_everything()).
  [[nodiscard]] Resegmentation resegment(const ChangeSet& changes) const;
  /// What process() applies for the first version: the whole map segmented and reconciled with every current
  /// box in scope. Also the anchor that shows what resegment() saves.
  [[nodiscard]] Resegmentation resegment_everything() const;

  /// The obstacle boxes, sorted by id.
  [[nodiscard]] const std::vector<Box>& boxes() const { return boxes_; }
  /// The unknown boxes, sorted by id (none when unknown space is not tracked, and before the first version).
  [[nodiscard]] const std::vector<Box>& unknown_boxes() const;
  /// What the cell publishes: the obstacle and the unknown boxes, sorted by id.
  [[nodiscard]] std::vector<Box> environment_boxes() const;
  /// The figures of the last cover of the whole workspace's unknown space, if unknown space is tracked and a
  /// cover was made since the start.
  [[nodiscard]] std::optional<UnknownCover> unknown_cover() const;
  /// The id the next new box gets: above every id this pipeline handed out or was started with.
  [[nodiscard]] std::uint64_t next_box_id() const { return next_box_id_; }
  [[nodiscard]] const OccupancyMap& map() const { return map_; }
  /// Occupied voxels of 26-connected occupied groups of at least `min_group` voxels that no single box holds
  /// whole: with min_group = change.min_voxels the obstacle voxels the boxes leave out (the safety property
  /// wants 0), with 1 every occupied voxel they leave out (noise included). Costs a pass over the map.
  [[nodiscard]] std::size_t voxels_outside_boxes(int min_group) const;
  /// The map, the viewpoint normals face and the change detector's state (the flips still waiting for
  /// confirmation, so that a restart confirms them as if it had not happened), as one opaque string (what a
  /// restart passes back to the constructor; also how a measurement clones a pipeline). The box-id counter is
  /// not part of it: it is kept with the versions (VersionStore), so a lost map state cannot bring back an
  /// id.
  [[nodiscard]] std::string map_state() const;

 private:
  // The region of every change, and the ids of the boxes the changes take away evidence from; those that
  // shrink in place give their new boxes instead of an area to re-segment.
  struct Scope {
    std::vector<Region> area;
    std::vector<std::uint64_t> boxes;
    std::vector<Box> shrunk;
    std::vector<Box> within;  // the boxes of `boxes` that lie wholly inside the area
  };
  [[nodiscard]] Scope scope_of(const ChangeSet& changes) const;
  // Whether `box`, which lost evidence to `changes`, shrinks in place (adds its box and the ids it replaces
  // to `scope`) instead of having its extent re-segmented.
  [[nodiscard]] bool shrink_in_place(const Box& box, const ChangeSet& changes, Scope& scope) const;
  // Adds to `scope` the boxes lying wholly inside its area (to a voxel).
  void add_boxes_within(Scope& scope) const;
  // Adds to `scope` the boxes that hold no obstacle voxel any more.
  void add_emptied_boxes(Scope& scope) const;
  // Boxes for the occupied voxels in `area` that no box of `kept` covers yet (their count and how they were
  // fitted go to `result`); `within`: the old boxes lying wholly in the area, which they may grow from.
  [[nodiscard]] std::vector<Box> fit_boxes(const std::vector<Region>& area, const std::vector<Box>& kept,
                                           const std::vector<Box>& within, Resegmentation& result) const;
  [[nodiscard]] std::optional<Box> one_tight_box(const Cloud& evidence, const std::vector<Box>& parts) const;
  // Makes the boxes of `reconciled` hold every obstacle voxel of the map whole (coverage.hpp).
  void cover_the_rest(Reconciled& reconciled) const;
  void restore(const std::string& map_state);
  void start_unknown(std::vector<Box>& boxes);
  void read_unknown_line(std::istream& in);
  void update_viewpoint(const Sweep& sweep);
  // Change detection and, when due, re-segmentation after the map took the sweep's update.
  void detect_and_resegment(const OccupancyUpdate& update, SweepReport& report);
  // Whether this sweep's changes (or the end of settling) call for re-segmentation; when they do, `changes`
  // holds every change gathered since the first that waits.
  [[nodiscard]] bool resegmentation_due(ChangeSet& changes);
  void apply(Resegmentation resegmentation, SweepReport& report);
  void accept_unboxed_vanishes();
  // Covers unknown space at the first version, then shrinks it as sweeps observe new voxels.
  void track_unknown(const OccupancyUpdate& update, bool resegmented, bool first_version,
                     SweepReport& report);
  // The robot's padded collision shapes as boxes in the cell frame, at the last robot pose a frame carried.
  [[nodiscard]] std::vector<Box> robot_body_C() const;

  CellPipelineConfig config_;
  std::unique_ptr<SelfFilter> filter_;  // set by filter_robot()
  std::optional<OpenSweep> open_;       // gathers the frames of process(FrameSweep)
  OccupancyMap map_;
  std::unique_ptr<OccupiedVoxels> occupied_;  // the map's occupied voxels, kept up sweep by sweep
  ChangeDetector detector_;
  std::vector<Box> boxes_;
  std::uint64_t next_box_id_;
  Eigen::Vector3d viewpoint_C_ = Eigen::Vector3d::Zero();  // where normals are oriented towards
  bool settling_ = true;                  // an empty map that has not made its first version yet
  int settled_sweeps_ = 0;                // sweeps fused while settling
  ChangeSet gathered_;                    // confirmed changes waiting to be published together
  int gather_wait_ = 0;                   // sweeps the gathered changes still wait
  std::optional<UnknownBoxes> unknown_;   // set when unknown space is tracked
  bool unknown_covered_ = false;          // this map's unknown space was covered (kept in the map state)
  bool unknown_due_ = false;              // a settled map whose unknown space was never covered: cover it now
  std::size_t observed_since_check_ = 0;  // voxels first observed since unknown space was last checked
  int sweeps_since_observed_ = 0;         // sweeps since the first of them
  std::vector<LinkBox> robot_parts_;      // the robot's collision shapes' bounding boxes, padded
  std::vector<std::size_t> robot_links_;  // the index of each part's link in Robot::link_names()
  std::optional<RobotAt> robot_at_;       // the robot at the last frame that carried its pose
};

}  // namespace cellmap
