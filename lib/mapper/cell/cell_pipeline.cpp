#include "cellmap/cell/cell_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <sstream>

#include "cellmap/common/error.hpp"

namespace cellmap::daemon {
namespace {

// Version 2 adds the viewpoint line (normals are oriented towards it, so a restart re-fits boxes alike);
// version 1 states (no viewpoint) are still read.
constexpr const char* kStateMagicV1 = "cellmap-map-state 1";
constexpr const char* kStateMagic = "cellmap-map-state 2";

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A point anywhere inside a voxel of edge r around a fitted centre lies within r/2 · ‖a‖₁ of it along a unit
// box axis a, so growing each half extent by that covers the whole voxel.
void grow_by_voxel(Box& box, double resolution) {
  const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
  for (int axis = 0; axis < 3; ++axis) box.half_extents[axis] += 0.5 * resolution * R.col(axis).lpNorm<1>();
}

}  // namespace

CellPipeline::CellPipeline(const DaemonConfig& config, std::vector<Box> boxes, std::uint64_t next_box_id,
                           const std::optional<std::string>& map_state)
    : config_(config),
      map_(config.occupancy),
      detector_(config.change),
      boxes_(std::move(boxes)),
      next_box_id_(next_box_id) {
  if (!map_state) return;
  settling_ = false;  // a restored map has settled before
  std::istringstream in(*map_state);
  std::string magic;
  std::getline(in, magic);
  std::uint64_t stored_next_id = 0;
  if ((magic != kStateMagic && magic != kStateMagicV1) || !(in >> stored_next_id) || in.get() != '\n') {
    throw Error("map state: not a cellmap map state (bad header)");
  }
  if (magic == kStateMagic) {
    Eigen::Vector3d viewpoint;
    if (!(in >> viewpoint.x() >> viewpoint.y() >> viewpoint.z()) || in.get() != '\n' ||
        !viewpoint.allFinite()) {
      throw Error("map state: bad viewpoint line");
    }
    viewpoint_C_ = viewpoint;
  }
  next_box_id_ = std::max(next_box_id_, stored_next_id);
  map_.read(in);
}

std::string CellPipeline::map_state() const {
  std::ostringstream out;
  out << kStateMagic << "\n" << next_box_id_ << "\n";
  out.precision(17);
  out << viewpoint_C_.x() << " " << viewpoint_C_.y() << " " << viewpoint_C_.z() << "\n";
  map_.write(out);
  return out.str();
}

SweepReport CellPipeline::process(const Sweep& sweep) {
  SweepReport report;
  report.points = sweep.point_count();
  if (!sweep.scans.empty()) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Scan& scan : sweep.scans) sum += scan.origin_C;
    viewpoint_C_ = sum / static_cast<double>(sweep.scans.size());
  }

  auto start = std::chrono::steady_clock::now();
  const OccupancyUpdate update = map_.integrate(sweep);
  report.t_fuse = seconds_since(start);
  report.hit_voxels = update.hit_voxels;
  report.free_voxels = update.free_voxels;
  report.flipped = update.appeared.size() + update.vanished.size();

  start = std::chrono::steady_clock::now();
  ChangeSet changes = detector_.update(update, map_);
  report.t_change = seconds_since(start);
  report.regions = changes.regions.size();
  report.boxes = boxes_.size();
  if (settling_ && ++settled_sweeps_ < config_.change.settle_sweeps) return report;
  if (!settling_ && changes.empty()) return report;

  start = std::chrono::steady_clock::now();
  // The map has settled: one segmentation of all of it makes the first version; changes from then on.
  Reconciled reconciled =
      settling_ ? resegment_everything(&report.evidence) : resegment(changes, &report.evidence);
  settling_ = false;
  report.t_segment = seconds_since(start);
  report.changes = std::move(changes);
  next_box_id_ = reconciled.next_id;
  if (reconciled.changed()) {
    boxes_ = reconciled.boxes;
    report.change = std::move(reconciled);
  }
  report.boxes = boxes_.size();
  return report;
}

Reconciled CellPipeline::resegment(const ChangeSet& changes, std::size_t* evidence) const {
  // Re-fit what the changes touch: the change regions, and the boxes that lost evidence (hold a vanished
  // voxel; their whole extent, so a partly changed object is fitted whole). A box that merely holds an
  // appeared voxel already covers it: re-fitting it (the table under a new object) would only churn ids.
  std::vector<Region> area;
  std::vector<Eigen::Vector3d> vanished_C;
  for (const ChangeRegion& region : changes.regions) {
    area.push_back(region.bounds);
    for (const octomap::OcTreeKey& key : region.vanished) vanished_C.push_back(map_.centre(key));
  }
  // A box re-fits only when it lost a tenth of its voxels: the table losing the few voxels an object removed
  // from it shared with its top layer keeps its boxes (still covering all it holds) instead of being split
  // anew.
  constexpr double kRefitShare = 0.1;
  std::vector<std::uint64_t> scope = boxes_touched(boxes_, vanished_C, kRefitShare);
  const auto in_scope = [&](const Box& box) {
    return std::find(scope.begin(), scope.end(), box.id) != scope.end();
  };
  for (const Box& box : boxes_) {
    if (in_scope(box)) area.push_back(bounds_of(box).grown(config_.change.margin));
  }
  const double resolution = map_.config().resolution;
  // Boxes lying wholly inside that area (to a voxel) join it: the top of a new object published a few sweeps
  // before its sides, or the part of a slightly moved object that appeared before its old place cleared, is
  // fitted again together with the rest of the object (same id, modified) instead of staying a box of its
  // own.
  for (const Box& box : boxes_) {
    const Region bounds = bounds_of(box);
    const auto holds = [&](const Region& r) {
      return r.grown(resolution).intersection(bounds).volume() >= bounds.volume();
    };
    if (!in_scope(box) && std::any_of(area.begin(), area.end(), holds)) scope.push_back(box.id);
  }
  std::vector<Box> kept;
  for (const Box& box : boxes_) {
    if (!in_scope(box)) kept.push_back(box);
  }
  return reconcile(boxes_, scope, fit_boxes(area, kept, evidence), next_box_id_, config_.reconcile);
}

std::vector<Box> CellPipeline::fit_boxes(const std::vector<Region>& area, const std::vector<Box>& kept,
                                         std::size_t* evidence) const {
  Cloud cloud;
  for (const Eigen::Vector3d& c : map_.occupied_centres(area)) {
    // Evidence a kept box already covers needs no new box (e.g. the table around a new object).
    const bool covered =
        std::any_of(kept.begin(), kept.end(), [&](const Box& box) { return box.contains(c); });
    if (!covered) cloud.push_back(pcl::PointXYZ(c.x(), c.y(), c.z()));
  }
  if (evidence != nullptr) *evidence = cloud.size();
  if (cloud.empty()) return {};
  cloud.sensor_origin_ = Eigen::Vector4f(viewpoint_C_.x(), viewpoint_C_.y(), viewpoint_C_.z(), 0.0f);
  SegmentResult result = segment_cloud(cloud, config_.segment);
  for (Box& box : result.boxes.boxes) grow_by_voxel(box, map_.config().resolution);
  return std::move(result.boxes.boxes);
}

std::vector<Box> CellPipeline::segment_everything(std::size_t* evidence) const {
  const octomap::OcTree& tree = map_.tree();
  double x0, y0, z0, x1, y1, z1;
  tree.getMetricMin(x0, y0, z0);
  tree.getMetricMax(x1, y1, z1);
  return fit_boxes({Region{{x0, y0, z0}, {x1, y1, z1}}.grown(tree.getResolution())}, {}, evidence);
}

Reconciled CellPipeline::resegment_everything(std::size_t* evidence) const {
  std::vector<std::uint64_t> scope;
  for (const Box& box : boxes_) scope.push_back(box.id);
  return reconcile(boxes_, scope, segment_everything(evidence), next_box_id_, config_.reconcile);
}

}  // namespace cellmap::daemon
