// SPDX-License-Identifier: Apache-2.0
#include "cellmap/cell/frame_grouper.hpp"

#include <algorithm>

namespace cellmap {

FrameGrouper::FrameGrouper(const SweepParams& grouping) : grouping_(grouping) {
  grouping_.validate();
}

FrameGrouper::Sensor& FrameGrouper::sensor(const std::string& name) {
  const auto it =
      std::find_if(sensors_.begin(), sensors_.end(), [&](const Sensor& s) { return s.name == name; });
  if (it != sensors_.end()) return *it;
  sensors_.push_back(Sensor{name});
  return sensors_.back();
}

void FrameGrouper::open(double stamp) {
  open_first_stamp_ = stamp;
  for (Sensor& s : sensors_) s.in_open = false;
}

// A frame older than the sensor's latest (out of order) tells nothing of its interval.
void FrameGrouper::note_frame(Sensor& sensor, double stamp) {
  if (sensor.seen && stamp > sensor.last) sensor.interval = stamp - sensor.last;
  if (!sensor.seen || stamp > sensor.last) sensor.last = stamp;
  sensor.seen = true;
  sensor.in_open = true;
}

// Stamps rounded in arithmetic (k / 30 s) must not miss the window's end by an ulp.
bool FrameGrouper::window_reached() const {
  const double end = open_first_stamp_ + grouping_.period;
  return std::all_of(sensors_.begin(), sensors_.end(), [&](const Sensor& s) {
    return !s.in_open || (s.interval > 0 && s.last + s.interval * (1 + 1e-6) >= end);
  });
}

FramePlace FrameGrouper::place(const std::string& name, double stamp) {
  FramePlace place;
  if (open_frames_ > 0 && stamp >= open_first_stamp_ + grouping_.period) {
    place.ends_open_sweep = true;
    open_frames_ = 0;
  }
  if (open_frames_ == 0) open(stamp);
  note_frame(sensor(name), stamp);
  ++open_frames_;
  const bool full = grouping_.max_frames > 0 && open_frames_ >= grouping_.max_frames;
  if (full || window_reached()) {
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
