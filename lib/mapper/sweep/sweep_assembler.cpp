// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sweep/sweep_assembler.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include "cellmap/common/error.hpp"

namespace cellmap {

void SweepParams::validate() const {
  if (!(period >= 0) || !std::isfinite(period)) throw Error("sweep grouping: period must be >= 0 seconds");
  if (!(pose_wait >= 0) || !std::isfinite(pose_wait))
    throw Error("sweep grouping: pose_wait must be >= 0 seconds");
}

SweepAssembler::SweepAssembler(const SweepParams& grouping, const Eigen::Isometry3d& X_ES)
    : grouping_(grouping), poser_(X_ES) {
  grouping_.validate();
}

void SweepAssembler::add(Frame frame, double now) {
  frame.depth.reset();  // only the points travel on; a 640x480 image is 600 kB per queued frame
  waiting_.push_back(Waiting{std::move(frame), now});
}

std::vector<Sweep> SweepAssembler::poll(const PoseBuffer& poses, double now) {
  std::vector<Sweep> done;
  pose_waiting(poses, now - grouping_.pose_wait, done);
  return done;
}

std::vector<Sweep> SweepAssembler::flush(const PoseBuffer& poses) {
  std::vector<Sweep> done;
  pose_waiting(poses, std::numeric_limits<double>::infinity(), done);
  if (!open_.scans.empty()) done.push_back(std::exchange(open_, Sweep{}));
  return done;
}

void SweepAssembler::pose_waiting(const PoseBuffer& poses, double give_up_before, std::vector<Sweep>& done) {
  while (!waiting_.empty()) {
    Waiting& head = waiting_.front();
    const PoseLookup found = poser_.attach(head.frame, poses);
    if (found == PoseLookup::kPending) {
      // Frames behind the head are newer: they wait too, unless the head waited long enough to give up.
      if (head.arrived > give_up_before) return;
      poser_.give_up();
    } else if (found == PoseLookup::kFound) {
      group(head.frame, done);
    }
    waiting_.pop_front();
  }
}

void SweepAssembler::group(const Frame& frame, std::vector<Sweep>& done) {
  if (!open_.scans.empty() && frame.stamp >= open_first_stamp_ + grouping_.period) {
    done.push_back(std::exchange(open_, Sweep{}));
  }
  if (open_.scans.empty()) open_first_stamp_ = frame.stamp;
  open_.scans.push_back(to_scan(frame));
  open_.stamp = frame.stamp;
  if (grouping_.max_frames > 0 && open_.scans.size() >= grouping_.max_frames) {
    done.push_back(std::exchange(open_, Sweep{}));
  }
}

}  // namespace cellmap
