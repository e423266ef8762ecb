#include "cellmap/cell/frame_grouper.hpp"

namespace cellmap {

FrameGrouper::FrameGrouper(const SweepParams& grouping) : grouping_(grouping) {
  grouping_.validate();
}

FramePlace FrameGrouper::place(double stamp) {
  FramePlace place;
  if (open_frames_ > 0 && stamp >= open_first_stamp_ + grouping_.period) {
    place.ends_open_sweep = true;
    open_frames_ = 0;
  }
  if (open_frames_ == 0) open_first_stamp_ = stamp;
  ++open_frames_;
  if (grouping_.max_frames > 0 && open_frames_ >= grouping_.max_frames) {
    place.completes_sweep = true;
    open_frames_ = 0;
  }
  return place;
}

bool FrameGrouper::flush() {
  const bool held = open_frames_ > 0;
  open_frames_ = 0;
  return held;
}

}  // namespace cellmap
