#include "cellmap/cell/frame_grouper.hpp"

#include <algorithm>
#include <utility>

namespace cellmap {

FrameGrouper::FrameGrouper(const SweepParams& grouping) : grouping_(grouping) {
  grouping_.validate();
}

std::vector<FrameSweep> FrameGrouper::add(SweepFrame frame) {
  std::vector<FrameSweep> done;
  if (!open_.frames.empty() && frame.frame.stamp >= open_first_stamp_ + grouping_.period)
    done.push_back(std::exchange(open_, FrameSweep{}));
  if (open_.frames.empty()) open_first_stamp_ = frame.frame.stamp;
  open_.stamp = std::max(open_.stamp, frame.frame.stamp);
  open_.frames.push_back(std::move(frame));
  if (grouping_.max_frames > 0 && open_.frames.size() >= grouping_.max_frames)
    done.push_back(std::exchange(open_, FrameSweep{}));
  return done;
}

std::optional<FrameSweep> FrameGrouper::flush() {
  if (open_.frames.empty()) return std::nullopt;
  return std::exchange(open_, FrameSweep{});
}

}  // namespace cellmap
