#include "cellmap/cell/open_sweep.hpp"

#include <algorithm>
#include <utility>

#include "cellmap/sweep/sweep.hpp"
#include "no_return.hpp"
#include "stage_clock.hpp"

namespace cellmap {
namespace {

// The frame as the sweep keeps it once fused: what it observed went into the voxels, its pose and what its
// sensor could see remain.
void drop_measurements(Frame& frame) {
  frame.points_S.clear();
  frame.points_S.points.shrink_to_fit();
  if (frame.depth) {
    frame.depth->depth.clear();
    frame.depth->depth.shrink_to_fit();
  }
}

}  // namespace

OpenSweep::OpenSweep(const OccupancyConfig& occupancy, const SelfFilter* filter)
    : occupancy_(occupancy), filter_(filter), open_(fresh()) {}

GatheredSweep OpenSweep::fresh() const {
  return GatheredSweep{{}, ObservedVoxels(occupancy_)};
}

void OpenSweep::add(SweepFrame frame) {
  const StageClock filter_clock;
  Scan scan;
  std::size_t robot_points = 0, no_return_rays = 0;
  if (filter_ && frame.robot) {
    SelfFilterResult filtered = filter_->filter(frame.frame, *frame.robot);
    robot_points = filtered.removed;
    scan = std::move(filtered.scan);
  } else {
    scan = move_to_scan(frame.frame);
  }
  if (frame.no_return_range > 0.0)
    no_return_rays = add_no_return_rays(frame.frame, frame.no_return_range, no_return_phase_++, scan);
  filter_clock.add_to(open_.t_filter, open_.cpu_filter);

  const StageClock gather_clock;
  const std::size_t points = scan.points_C.size();
  const Eigen::Vector3d origin_C = scan.origin_C;
  open_.voxels.add(std::move(scan));
  gather_clock.add_to(open_.t_gather, open_.cpu_gather);

  open_.points += points;
  open_.robot_points += robot_points;
  open_.no_return_rays += no_return_rays;
  origin_sum_C_ += origin_C;
  drop_measurements(frame.frame);
  FrameSweep& frames = open_.frames;
  frames.stamp = frames.frames.empty() ? frame.frame.stamp : std::max(frames.stamp, frame.frame.stamp);
  frames.frames.push_back(std::move(frame));
}

GatheredSweep OpenSweep::close() {
  if (!open_.frames.frames.empty())
    open_.viewpoint_C = origin_sum_C_ / static_cast<double>(open_.frames.frames.size());
  origin_sum_C_.setZero();
  return std::exchange(open_, fresh());
}

}  // namespace cellmap
