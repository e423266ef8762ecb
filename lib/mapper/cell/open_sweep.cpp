// SPDX-License-Identifier: Apache-2.0
#include "cellmap/cell/open_sweep.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include "cellmap/common/error.hpp"
#include "cellmap/common/parallel.hpp"
#include "cellmap/sweep/sweep.hpp"
#include "no_return.hpp"
#include "stage_clock.hpp"

namespace cellmap {
namespace {

// The frame as the sweep keeps it once gathered: what it observed went into the voxels, its pose and what
// its sensor could see remain.
void drop_measurements(Frame& frame) {
  frame.points_S.clear();
  frame.points_S.points.shrink_to_fit();
  frame.no_return_S.clear();
  frame.no_return_S.points.shrink_to_fit();
  if (frame.depth) {
    frame.depth->depth.clear();
    frame.depth->depth.shrink_to_fit();
  }
}

// Points of `scan` outside `workspace` become clear-only ray ends.
void clear_only_outside(const Workspace& workspace, Scan& scan) {
  Cloud inside;
  inside.reserve(scan.points_C.size());
  for (const pcl::PointXYZ& p : scan.points_C) {
    (workspace.contains(p.getVector3fMap().cast<double>()) ? inside : scan.clear_C).push_back(p);
  }
  scan.points_C = std::move(inside);
  set_unorganized(scan.points_C);
  set_unorganized(scan.clear_C);
}

// The start of the line that says why `frame` was left out.
std::string fault_of(const SweepFrame& frame) {
  return "frame of '" + frame.frame.sensor + "' at " + std::to_string(frame.frame.stamp) + " s: ";
}

}  // namespace

OpenSweep::OpenSweep(const OccupancyConfig& occupancy, const SelfFilter* filter,
                     std::optional<Workspace> workspace)
    : occupancy_(occupancy), filter_(filter), workspace_(std::move(workspace)), open_(fresh()) {
  side_by_side_.reserve(std::size_t(std::max(occupancy_.threads, 1)));
  for (int t = 0; t < std::max(occupancy_.threads, 1); ++t) side_by_side_.emplace_back(occupancy_);
}

GatheredSweep OpenSweep::fresh() const {
  return GatheredSweep{{}, ObservedVoxels(occupancy_)};
}

OpenSweep::Gathered OpenSweep::gather(SweepFrame frame, unsigned phase, ObservedVoxels& voxels,
                                      int threads) const {
  Gathered out;
  const StageClock filter_clock;
  Scan scan;
  if (filter_ && frame.robot) {
    SelfFilterResult filtered = filter_->filter(frame.frame, *frame.robot);
    out.robot_points = filtered.removed;
    scan = std::move(filtered.scan);
  } else {
    scan = move_to_scan(frame.frame);
  }
  if (workspace_) clear_only_outside(*workspace_, scan);
  if (frame.no_return_range > 0.0)
    out.no_return_rays = add_no_return_rays(frame.frame, frame.no_return_range, phase, scan);
  filter_clock.add_to(out.t_filter, out.cpu_filter);

  const StageClock gather_clock;
  out.points = scan.points_C.size();
  out.origin_C = scan.origin_C;
  voxels.add(std::move(scan), threads);
  gather_clock.add_to(out.t_gather, out.cpu_gather);
  drop_measurements(frame.frame);
  out.frame = std::move(frame);
  return out;
}

void OpenSweep::record(Gathered gathered) {
  open_.points += gathered.points;
  open_.robot_points += gathered.robot_points;
  open_.no_return_rays += gathered.no_return_rays;
  open_.t_filter += gathered.t_filter;
  open_.cpu_filter += gathered.cpu_filter;
  open_.t_gather += gathered.t_gather;
  open_.cpu_gather += gathered.cpu_gather;
  origin_sum_C_ += gathered.origin_C;
  FrameSweep& frames = open_.frames;
  const double stamp = gathered.frame.frame.stamp;
  frames.stamp = frames.frames.empty() ? stamp : std::max(frames.stamp, stamp);
  frames.frames.push_back(std::move(gathered.frame));
}

unsigned OpenSweep::next_phase(const SweepFrame& frame) {
  return frame.no_return_range > 0.0 ? no_return_phase_++ : 0;
}

void OpenSweep::add(SweepFrame frame) {
  const auto start = std::chrono::steady_clock::now();
  const unsigned phase = next_phase(frame);
  record(gather(std::move(frame), phase, side_by_side_[0], occupancy_.threads));
  open_.t_gathering += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<std::string> OpenSweep::add(std::vector<SweepFrame> batch) {
  std::vector<std::string> faults;
  const int threads = std::min(int(side_by_side_.size()), int(batch.size()));
  if (threads <= 1) {
    for (SweepFrame& frame : batch) {
      const std::string fault = fault_of(frame);
      try {
        add(std::move(frame));
      } catch (const Error& e) {
        faults.push_back(fault + e.what());
      }
    }
    return faults;
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::optional<Gathered>> gathered(batch.size());
  std::vector<std::string> reasons;
  std::vector<unsigned> phases;
  for (const SweepFrame& frame : batch) {
    phases.push_back(next_phase(frame));
    reasons.push_back(fault_of(frame));
  }
  // Thread t gathers frames t, t + threads, … into side_by_side_[t]: no two threads share voxels.
  parallel_for(threads, threads, [&](int t) {
    for (std::size_t i = std::size_t(t); i < batch.size(); i += std::size_t(threads)) {
      try {
        gathered[i] = gather(std::move(batch[i]), phases[i], side_by_side_[std::size_t(t)], 1);
      } catch (const Error& e) {
        reasons[i] += e.what();
      }
    }
  });
  for (std::size_t i = 0; i < batch.size(); ++i) {
    if (gathered[i]) {
      record(std::move(*gathered[i]));
    } else {
      faults.push_back(std::move(reasons[i]));
    }
  }
  open_.t_gathering += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return faults;
}

GatheredSweep OpenSweep::close() {
  if (!open_.frames.frames.empty())
    open_.viewpoint_C = origin_sum_C_ / static_cast<double>(open_.frames.frames.size());
  origin_sum_C_.setZero();
  for (ObservedVoxels& voxels : side_by_side_) open_.voxels.merge(voxels);
  return std::exchange(open_, fresh());
}

}  // namespace cellmap
