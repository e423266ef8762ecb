// SPDX-License-Identifier: Apache-2.0
#include "cellmap/cell/cell_pipeline.hpp"

#include <algorithm>
#include <limits>
#include <sstream>
#include <string_view>

#include "cellmap/common/error.hpp"
#include "cellmap/segment/free_space.hpp"
#include "coverage.hpp"
#include "stage_clock.hpp"

namespace cellmap {
namespace {

// The map state's first line. Version 4 adds the change detector's state (its pending flips belong to the
// map they flipped in); version 3 (viewpoint and map) is still read, with no flip pending. Versions 2
// (counter + viewpoint) and 1 (counter only) also carried the box-id counter, which now is kept with the
// versions, where a lost map cannot take it along; it raises the one the pipeline was given.
constexpr std::string_view kStateMagicV1 = "cellmap-map-state 1";
constexpr std::string_view kStateMagicV2 = "cellmap-map-state 2";
constexpr std::string_view kStateMagicV3 = "cellmap-map-state 3";
constexpr std::string_view kStateMagicV4 = "cellmap-map-state 4";
constexpr std::string_view kStateMagic = "cellmap-map-state 5";
constexpr std::string_view kUnknownCovered = "unknown-space covered";
constexpr std::string_view kUnknownNotCovered = "unknown-space not-covered";

// A box re-fits only when it lost a tenth of its voxels: the table losing the few voxels an object removed
// from it shared with its top layer keeps its boxes (still covering all it holds) instead of being split
// anew.
constexpr double kRefitShare = 0.1;

bool contains_id(const std::vector<std::uint64_t>& ids, std::uint64_t id) {
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}

// The smallest box in `like`'s rotation that holds the voxel of edge `voxel` around every point whole.
Box box_in_rotation(const Cloud& centres, const Box& like, double voxel) {
  const Eigen::Matrix3d R = like.rotation.toRotationMatrix();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const pcl::PointXYZ& p : centres) {
    const Eigen::Vector3d local = R.transpose() * (p.getVector3fMap().cast<double>() - like.center);
    lo = lo.cwiseMin(local);
    hi = hi.cwiseMax(local);
  }
  Box box = like;
  box.center = like.center + R * (0.5 * (lo + hi));
  box.half_extents = (0.5 * (hi - lo)).array() + kBoxFitSlack;
  box.points = centres.size();
  grow_to_hold_cubes(box, voxel);
  return box;
}

// The space seen free around voxel centres, judged as the segmentation judges its boxes (box_split.hpp):
// direction bins a voxel wide at the median range, surfaces a voxel thick.
SeenFreeSpace seen_free_around(const Cloud& centres, const Eigen::Vector3d& viewpoint, double voxel) {
  std::vector<int> indices(centres.size());
  std::vector<double> range(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    indices[i] = static_cast<int>(i);
    range[i] = (centres[i].getVector3fMap().cast<double>() - viewpoint).norm();
  }
  std::nth_element(range.begin(), range.begin() + range.size() / 2, range.end());
  const double step = voxel / std::max(range[range.size() / 2], 10 * voxel);
  return SeenFreeSpace(centres, indices, viewpoint, step, voxel);
}

// The share of `box`'s volume seen free around the voxel centres it holds.
double seen_free_share(const Cloud& centres, const Box& box, const Eigen::Vector3d& viewpoint, double voxel) {
  return seen_free_around(centres, viewpoint, voxel).free_volume(box) / box.volume();
}

// The free space (as `seen` judges it) that `parts` block, each shrunk in its rotation to the voxels of
// `centres` it holds (each voxel counted in the first part holding it); parts holding none block nothing.
double free_volume_of_parts(const Cloud& centres, const std::vector<Box>& parts, const SeenFreeSpace& seen,
                            double voxel) {
  std::vector<Cloud> held(parts.size());
  for (const pcl::PointXYZ& p : centres) {
    const Eigen::Vector3d c = p.getVector3fMap().cast<double>();
    for (std::size_t i = 0; i < parts.size(); ++i) {
      if (!parts[i].contains(c)) continue;
      held[i].push_back(p);
      break;
    }
  }
  double free = 0.0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!held[i].empty()) free += seen.free_volume(box_in_rotation(held[i], parts[i], voxel));
  }
  return free;
}

// Whether something appeared in `changes` (else they only remove).
bool appears(const ChangeSet& changes) {
  return std::any_of(changes.regions.begin(), changes.regions.end(),
                     [](const ChangeRegion& region) { return !region.appeared.empty(); });
}

}  // namespace

CellPipeline::CellPipeline(const CellPipelineConfig& config, std::vector<Box> boxes,
                           std::uint64_t next_box_id, const std::optional<std::string>& map_state)
    : config_(config),
      map_(config.occupancy),
      occupied_(std::make_unique<OccupiedVoxels>()),
      detector_(config.change),
      boxes_(std::move(boxes)),
      next_box_id_(next_box_id) {
  // The points segmented are occupied voxel centres: boxes hold the whole voxels. The threads that cast a
  // sweep's rays are idle while it is segmented (the daemon's gathering waits for its version).
  config_.segment.voxel = config_.occupancy.resolution;
  config_.segment.threads = config_.occupancy.threads;
  if (config_.settle_sweeps < 0 || config_.settle_sweeps > 100000)
    throw Error("change.settle_sweeps: must be an integer in [0, 100000], got " +
                std::to_string(config_.settle_sweeps));
  if (config_.gather_sweeps < 0 || config_.gather_sweeps > 1000)
    throw Error("change.gather_sweeps: must be an integer in [0, 1000], got " +
                std::to_string(config_.gather_sweeps));
  if (map_state) restore(*map_state);
  start_unknown(boxes_);
}

// Splits the boxes the cell started from: obstacle boxes stay, unknown boxes go to the tracker (or are
// dropped when unknown space is not tracked: the next version removes them).
void CellPipeline::start_unknown(std::vector<Box>& boxes) {
  std::vector<Box> unknown;
  const auto is_unknown = [](const Box& b) { return b.space == BoxSpace::kUnknown; };
  std::copy_if(boxes.begin(), boxes.end(), std::back_inserter(unknown), is_unknown);
  boxes.erase(std::remove_if(boxes.begin(), boxes.end(), is_unknown), boxes.end());
  if (!config_.unknown.active()) return;
  unknown_.emplace(config_.unknown, unknown);
  unknown_due_ = !settling_ && !unknown_covered_;
}

CellPipeline::~CellPipeline() = default;
CellPipeline::CellPipeline(CellPipeline&&) noexcept = default;
CellPipeline& CellPipeline::operator=(CellPipeline&&) noexcept = default;

void CellPipeline::restore(const std::string& map_state) {
  settling_ = false;  // a restored map has settled before
  std::istringstream in(map_state);
  std::string magic;
  std::getline(in, magic);
  if (magic != kStateMagic && magic != kStateMagicV4 && magic != kStateMagicV3 && magic != kStateMagicV2 &&
      magic != kStateMagicV1)
    throw Error("map state: not a cellmap map state (bad header)");
  if (magic == kStateMagicV2 || magic == kStateMagicV1) {
    std::uint64_t legacy_next_id = 0;
    if (!(in >> legacy_next_id) || in.get() != '\n') throw Error("map state: bad box-id counter line");
    next_box_id_ = std::max(next_box_id_, legacy_next_id);
  }
  if (magic != kStateMagicV1) {
    Eigen::Vector3d viewpoint;
    if (!(in >> viewpoint.x() >> viewpoint.y() >> viewpoint.z()) || in.get() != '\n' ||
        !viewpoint.allFinite()) {
      throw Error("map state: bad viewpoint line");
    }
    viewpoint_C_ = viewpoint;
  }
  try {
    if (magic == kStateMagic || magic == kStateMagicV4) detector_.read(in);
  } catch (const Error& e) {
    throw Error(std::string("map state: ") + e.what());
  }
  if (magic == kStateMagic) read_unknown_line(in);
  map_.read(in);
  *occupied_ = OccupiedVoxels(map_);
}

void CellPipeline::read_unknown_line(std::istream& in) {
  std::string line;
  std::getline(in, line);
  if (line != kUnknownCovered && line != kUnknownNotCovered) throw Error("map state: bad unknown-space line");
  unknown_covered_ = line == kUnknownCovered;
}

std::string CellPipeline::map_state() const {
  std::ostringstream out;
  out << kStateMagic << "\n";
  out.precision(17);
  out << viewpoint_C_.x() << " " << viewpoint_C_.y() << " " << viewpoint_C_.z() << "\n";
  detector_.write(out);
  out << (unknown_covered_ ? kUnknownCovered : kUnknownNotCovered) << "\n";
  map_.write(out);
  return out.str();
}

std::size_t CellPipeline::settle_on(const Cloud& points_C) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(points_C.size());
  for (const pcl::PointXYZ& p : points_C) points.push_back(p.getVector3fMap().cast<double>());
  viewpoint_C_ = points_C.sensor_origin_.head<3>().cast<double>();
  settling_ = false;
  const std::size_t outside = map_.mark_occupied(points);
  *occupied_ = OccupiedVoxels(map_);
  return outside;
}

void CellPipeline::filter_robot(const Robot& robot) {
  filter_ = std::make_unique<SelfFilter>(robot, config_.self_filter);
  robot_parts_ = robot.shape_boxes();
  for (LinkBox& part : robot_parts_) {
    part.half_extents = part.half_extents * config_.self_filter.padding_scale +
                        Eigen::Vector3d::Constant(config_.self_filter.padding);
  }
  robot_links_.assign(robot.shape_links().begin(), robot.shape_links().end());
  open_.reset();
}

OpenSweep CellPipeline::open_sweep() const {
  return OpenSweep(config_.occupancy, config_.self_filter.enabled ? filter_.get() : nullptr,
                   config_.segment.workspace);
}

SweepReport CellPipeline::process(FrameSweep sweep) {
  if (!open_) open_.emplace(open_sweep());
  for (SweepFrame& frame : sweep.frames) open_->add(std::move(frame));
  GatheredSweep gathered = open_->close();
  return process(gathered);
}

SweepReport CellPipeline::process(GatheredSweep& sweep) {
  SweepReport report;
  report.points = sweep.points;
  report.frames = sweep.frames.frames.size();
  report.robot_points = sweep.robot_points;
  report.no_return_rays = sweep.no_return_rays;
  report.t_filter = sweep.t_filter;
  report.cpu_filter = sweep.cpu_filter;
  report.t_gathering = sweep.t_gathering;
  if (!sweep.frames.frames.empty()) viewpoint_C_ = sweep.viewpoint_C;
  for (const SweepFrame& frame : sweep.frames.frames) {
    if (frame.robot) robot_at_ = frame.robot;
  }

  const StageClock update_clock;
  const OccupancyUpdate update = map_.integrate(sweep.voxels);
  update_clock.add_to(report.t_update, report.cpu_update);
  report.t_fuse = sweep.t_gather + report.t_update;
  report.cpu_fuse = sweep.cpu_gather + report.cpu_update;
  detect_and_resegment(update, report);
  return report;
}

SweepReport CellPipeline::process(const Sweep& sweep) {
  SweepReport report;
  report.points = sweep.point_count();
  report.frames = sweep.scans.size();
  update_viewpoint(sweep);

  const StageClock fuse_clock;
  const OccupancyUpdate update = map_.integrate(sweep);
  fuse_clock.add_to(report.t_fuse, report.cpu_fuse);
  report.t_update = report.t_fuse;
  report.cpu_update = report.cpu_fuse;
  detect_and_resegment(update, report);
  return report;
}

void CellPipeline::detect_and_resegment(const OccupancyUpdate& update, SweepReport& report) {
  occupied_->apply(update);
  report.hit_voxels = update.hit_voxels;
  report.free_voxels = update.free_voxels;
  report.flipped = update.appeared.size() + update.vanished.size();

  const StageClock change_clock;
  ChangeSet changes = detector_.update(update, map_);
  change_clock.add_to(report.t_change, report.cpu_change);
  report.regions = changes.regions.size();
  report.boxes = boxes_.size();

  const bool due = resegmentation_due(changes);
  const bool first_version = due && settling_;
  if (due) {
    const StageClock segment_clock;
    // The map has settled: one segmentation of all of it makes the first version; changes from then on.
    Resegmentation resegmentation = settling_ ? resegment_everything() : resegment(changes);
    settling_ = false;
    segment_clock.add_to(report.t_segment, report.cpu_segment);
    report.changes = std::move(changes);
    apply(std::move(resegmentation), report);
  }
  track_unknown(update, due, first_version, report);
}

// Unknown space shrinks as sweeps observe voxels never observed before. Those are checked together with the
// next re-segmentation, so that an object coming into view with the space behind it (a crate taken away)
// is one version; or check_sweeps sweeps after the first of them, when no change follows.
void CellPipeline::track_unknown(const OccupancyUpdate& update, bool resegmented, bool first_version,
                                 SweepReport& report) {
  if (!unknown_) return;
  if (update.newly_observed > 0 || observed_since_check_ > 0) ++sweeps_since_observed_;
  observed_since_check_ += update.newly_observed;
  const bool cover = first_version || (unknown_due_ && !settling_);
  const bool check = !settling_ && observed_since_check_ > 0 &&
                     (resegmented || sweeps_since_observed_ >= config_.unknown.check_sweeps);
  if (cover || check) {
    const StageClock clock;
    double cpu = 0;
    std::vector<Box> held = robot_body_C();
    held.insert(held.end(), boxes_.begin(), boxes_.end());
    report.unknown =
        cover ? unknown_->cover_all(map_, held, next_box_id_) : unknown_->shrink(map_, held, next_box_id_);
    clock.add_to(report.t_unknown, cpu);
    report.unknown_covered = cover;
    unknown_covered_ = unknown_covered_ || cover;
    unknown_due_ = false;
    observed_since_check_ = 0;
    sweeps_since_observed_ = 0;
  }
  report.unknown_boxes = unknown_->boxes().size();
}

std::vector<Box> CellPipeline::robot_body_C() const {
  std::vector<Box> body;
  if (!robot_at_) return body;
  for (std::size_t i = 0; i < robot_parts_.size(); ++i) {
    if (robot_links_[i] >= robot_at_->X_CL.size()) continue;
    const Eigen::Isometry3d X_CB = robot_at_->X_CL[robot_links_[i]] * robot_parts_[i].X_LB;
    Box part;
    part.center = X_CB.translation();
    part.rotation = Eigen::Quaterniond(X_CB.rotation());
    part.half_extents = robot_parts_[i].half_extents;
    body.push_back(part);
  }
  return body;
}

const std::vector<Box>& CellPipeline::unknown_boxes() const {
  static const std::vector<Box> kNone;
  return unknown_ ? unknown_->boxes() : kNone;
}

std::vector<Box> CellPipeline::environment_boxes() const {
  std::vector<Box> all = boxes_;
  const std::vector<Box>& unknown = unknown_boxes();
  all.insert(all.end(), unknown.begin(), unknown.end());
  std::sort(all.begin(), all.end(), [](const Box& a, const Box& b) { return a.id < b.id; });
  return all;
}

std::optional<UnknownCover> CellPipeline::unknown_cover() const {
  if (!unknown_ || unknown_->last_cover().grid_volume <= 0) return std::nullopt;
  return unknown_->last_cover();
}

void CellPipeline::update_viewpoint(const Sweep& sweep) {
  if (sweep.scans.empty()) return;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Scan& scan : sweep.scans) sum += scan.origin_C;
  viewpoint_C_ = sum / static_cast<double>(sweep.scans.size());
}

bool CellPipeline::resegmentation_due(ChangeSet& changes) {
  if (settling_) return ++settled_sweeps_ >= config_.settle_sweeps;
  if (!changes.empty()) {
    if (gathered_.empty())
      gather_wait_ = (config_.gather_removals || appears(changes)) ? config_.gather_sweeps : 0;
    for (ChangeRegion& region : changes.regions) gathered_.regions.push_back(std::move(region));
  }
  if (gathered_.empty() || gather_wait_-- > 0) return false;
  changes.regions = std::move(gathered_.regions);
  gathered_.regions.clear();
  return true;
}

void CellPipeline::apply(Resegmentation resegmentation, SweepReport& report) {
  Reconciled& reconciled = resegmentation.reconciled;
  report.evidence = resegmentation.evidence;
  next_box_id_ = reconciled.next_id;
  if (reconciled.changed()) {
    boxes_ = reconciled.boxes;
    accept_unboxed_vanishes();
    report.change = std::move(reconciled);
  }
  report.boxes = boxes_.size();
}

// A voxel that has vanished from the map but not yet by the change detector's count, and that no box holds
// any more, counts as gone for the detector from now on: the boxes let it go, so its object coming back
// before the detector would have confirmed the removal must be reported, not taken for the voxel falling
// back to its confirmed state (which would leave it outside every box, unreported).
void CellPipeline::accept_unboxed_vanishes() {
  CubeHolders held(boxes_, map_.config().resolution);
  std::vector<octomap::OcTreeKey> unboxed;
  for (const octomap::OcTreeKey& key : detector_.pending_vanished()) {
    if (!held.hold(map_.centre(key))) unboxed.push_back(key);
  }
  detector_.accept_vanished(unboxed);
}

Resegmentation CellPipeline::resegment(const ChangeSet& changes) const {
  Scope scope = scope_of(changes);
  add_boxes_within(scope);
  add_emptied_boxes(scope);
  std::vector<Box> kept = scope.shrunk;
  for (const Box& box : boxes_) {
    if (!contains_id(scope.boxes, box.id)) kept.push_back(box);
  }
  Resegmentation result;
  std::vector<Box> fitted = fit_boxes(scope.area, kept, scope.within, result);
  fitted.insert(fitted.end(), scope.shrunk.begin(), scope.shrunk.end());
  result.reconciled = reconcile(boxes_, scope.boxes, fitted, next_box_id_, config_.reconcile);
  // Noise alone makes no version: what it added is taken up by the next version a change makes.
  if (config_.cover_every_version && result.reconciled.changed()) cover_the_rest(result.reconciled);
  return result;
}

// Re-fits what the changes touch: the change regions, and the boxes that lost evidence (hold a vanished
// voxel; their whole extent, so a partly changed object is fitted whole). A box that merely holds an
// appeared voxel already covers it: re-fitting it (the table under a new object) would only churn ids.
CellPipeline::Scope CellPipeline::scope_of(const ChangeSet& changes) const {
  Scope scope;
  std::vector<Eigen::Vector3d> vanished_C;
  for (const ChangeRegion& region : changes.regions) {
    scope.area.push_back(region.bounds);
    for (const octomap::OcTreeKey& key : region.vanished) vanished_C.push_back(map_.centre(key));
  }
  const std::vector<std::uint64_t> touched = boxes_touched(boxes_, vanished_C, kRefitShare);
  for (const Box& box : boxes_) {
    if (!contains_id(touched, box.id) || contains_id(scope.boxes, box.id)) continue;
    scope.boxes.push_back(box.id);
    if (!shrink_in_place(box, changes, scope))
      scope.area.push_back(bounds_of(box).grown(config_.change.margin));
  }
  return scope;
}

// An object taken away from beside another leaves the box they were joined into with the other's voxels:
// the box of what it still holds, in its own rotation, is what re-segmenting its extent ends in when that
// box blocks no more seen free space than a join accepts. The boxes within the margin of it are taken in
// (the part of a slightly moved object that got a box of its own); when something appeared there, the
// object changed rather than lost a part, and its extent is re-segmented.
bool CellPipeline::shrink_in_place(const Box& box, const ChangeSet& changes, Scope& scope) const {
  const double resolution = map_.config().resolution;
  const Region reach = bounds_of(box).grown(config_.change.margin);
  for (const ChangeRegion& region : changes.regions) {
    if (reach.intersection(region.bounds).volume() <= 0) continue;
    for (const octomap::OcTreeKey& key : region.appeared) {
      if (reach.contains(map_.centre(key))) return false;
    }
  }
  std::vector<const Box*> taken_in{&box}, neighbours;
  for (const Box& other : boxes_) {
    if (other.id == box.id) continue;
    const Region bounds = bounds_of(other);
    if (reach.grown(resolution).intersection(bounds).volume() >= bounds.volume()) {
      if (contains_id(scope.boxes, other.id)) return false;  // re-segmented already
      taken_in.push_back(&other);
    } else if (reach.intersection(bounds).volume() > 0) {
      neighbours.push_back(&other);
    }
  }
  Cloud evidence;
  for (const Eigen::Vector3d& c : map_.occupied_centres({reach})) {
    const auto holds_centre = [&](const Box* b) { return b->contains(c); };
    const auto holds_voxel = [&](const Box* b) { return holds_cube(*b, c, resolution); };
    if (std::none_of(taken_in.begin(), taken_in.end(), holds_centre) ||
        std::any_of(neighbours.begin(), neighbours.end(), holds_voxel) ||
        !occupied_->in_group_of(map_, c, config_.change.min_voxels)) {
      continue;
    }
    evidence.push_back(pcl::PointXYZ(c.x(), c.y(), c.z()));
  }
  if (evidence.empty()) return false;  // it goes: nothing to shrink to
  const Box shrunk = box_in_rotation(evidence, box, resolution);
  if (seen_free_share(evidence, shrunk, viewpoint_C_, resolution) > config_.segment.join_max_growth)
    return false;
  scope.shrunk.push_back(shrunk);
  for (const Box* b : taken_in) {
    if (b != &box) scope.boxes.push_back(b->id);
  }
  return true;
}

// Boxes lying wholly inside the area (to a voxel) join it: the top of a new object published a few sweeps
// before its sides, or the part of a slightly moved object that appeared before its old place cleared, is
// fitted again together with the rest of the object (same id, modified) instead of staying a box of its own.
void CellPipeline::add_boxes_within(Scope& scope) const {
  const double resolution = map_.config().resolution;
  for (const Box& box : boxes_) {
    const Region bounds = bounds_of(box);
    const auto holds = [&](const Region& r) {
      return r.grown(resolution).intersection(bounds).volume() >= bounds.volume();
    };
    if (!contains_id(scope.boxes, box.id) && std::any_of(scope.area.begin(), scope.area.end(), holds)) {
      scope.boxes.push_back(box.id);
      scope.within.push_back(box);
    }
  }
}

// Boxes that hold no obstacle voxel any more join the scope (and, with nothing to fit, go): the rest of an
// object's old place that cleared piece by piece after its change was published (hidden by the robot then),
// each piece beside voxels not yet cleared and so never a change region of its own.
void CellPipeline::add_emptied_boxes(Scope& scope) const {
  for (const Box& box : boxes_) {
    if (contains_id(scope.boxes, box.id)) continue;
    const bool holds_evidence =
        map_.any_occupied_in(bounds_of(box), [&](const octomap::OcTreeKey& key, const Eigen::Vector3d& c) {
          return box.contains(c) && occupied_->in_group_of(key, config_.change.min_voxels);
        });
    if (!holds_evidence) scope.boxes.push_back(box.id);
  }
}

std::vector<Box> CellPipeline::fit_boxes(const std::vector<Region>& area, const std::vector<Box>& kept,
                                         const std::vector<Box>& within, Resegmentation& result) const {
  Cloud cloud;
  CubeHolders kept_boxes(kept, map_.config().resolution);
  for (const Eigen::Vector3d& c : map_.occupied_centres(area)) {
    // A group of fewer than change.min_voxels voxels touching nothing else is noise (flying pixels that
    // collected their hits where no ray clears them), as for change detection: not an obstacle.
    if (!occupied_->in_group_of(map_, c, config_.change.min_voxels)) continue;
    // Evidence a kept box already holds needs no new box (e.g. the table around a new object).
    if (!kept_boxes.hold(c)) cloud.push_back(pcl::PointXYZ(c.x(), c.y(), c.z()));
  }
  result.evidence = cloud.size();
  if (cloud.empty()) return {};
  if (std::optional<Box> box = one_tight_box(cloud, within)) {
    result.one_tight_box = true;
    return {*box};
  }
  cloud.sensor_origin_ = Eigen::Vector4f(viewpoint_C_.x(), viewpoint_C_.y(), viewpoint_C_.z(), 0.0f);
  return segment_cloud(cloud, config_.segment).boxes.boxes;
}

// Evidence that is one connected piece is one box when that box blocks at most join_max_growth of its
// volume more seen free space than the boxes it grows from, `parts` (boxes the change area took whole, each
// shrunk to the evidence it holds; none for a new object: then it must block at most that share in all).
// That is the join rule: the segmentation would join any parts it cut the evidence into, and no cut frees
// min_gain (> join_max_growth) of it. Such is a compact object on its own, or a surface coming into view
// piece by piece beside its old box (the floor beyond the table's end); segmenting it would end in the same
// box at several times the cost.
std::optional<Box> CellPipeline::one_tight_box(const Cloud& cloud, const std::vector<Box>& parts) const {
  if (config_.segment.split_method != SplitMethod::kFreeSpace || config_.segment.join_max_growth <= 0)
    return std::nullopt;
  const double voxel = map_.config().resolution;
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(cloud.size());
  for (const pcl::PointXYZ& p : cloud) centres.push_back(p.getVector3fMap().cast<double>());
  if (connected_groups(centres, voxel).size() != 1) return std::nullopt;
  const Box box = fit_box(centres, config_.segment.box_kind, voxel);
  const SeenFreeSpace seen = seen_free_around(cloud, viewpoint_C_, voxel);
  const double growth = seen.free_volume(box) - free_volume_of_parts(cloud, parts, seen, voxel);
  if (growth > config_.segment.join_max_growth * box.volume()) return std::nullopt;
  return box;
}

Resegmentation CellPipeline::resegment_everything() const {
  const octomap::OcTree& tree = map_.tree();
  double x0, y0, z0, x1, y1, z1;
  tree.getMetricMin(x0, y0, z0);
  tree.getMetricMax(x1, y1, z1);
  const Region whole = Region{{x0, y0, z0}, {x1, y1, z1}}.grown(tree.getResolution());
  std::vector<std::uint64_t> scope;
  for (const Box& box : boxes_) scope.push_back(box.id);
  Resegmentation result;
  const std::vector<Box> fitted = fit_boxes({whole}, {}, {}, result);
  result.reconciled = reconcile(boxes_, scope, fitted, next_box_id_, config_.reconcile);
  cover_the_rest(result.reconciled);
  return result;
}

std::size_t CellPipeline::voxels_outside_boxes(int min_group) const {
  return voxels_outside(map_, *occupied_, boxes_, min_group).size();
}

// Every obstacle voxel wholly inside a box at every version: also those that noise added outside the changed
// area since that area was last fitted (a surface seen at grazing angles filling in, flying pixels collecting
// their hits in space no ray clears) and those a box kept by reconcile within its tolerance leaves out.
void CellPipeline::cover_the_rest(Reconciled& reconciled) const {
  CoverParams options;
  options.voxel = map_.config().resolution;
  options.max_growth = config_.segment.join_max_growth;
  options.reach = 2 * options.voxel;  // a surface's noise moves it by about a voxel
  options.kind = config_.segment.box_kind;
  cover(reconciled,
        voxels_outside(map_, *occupied_, reconciled.boxes, config_.change.min_voxels,
                       config_.occupancy.threads),
        options);
}

}  // namespace cellmap
