// SPDX-License-Identifier: Apache-2.0
#pragma once
// How the posed frames of a cell's sensors (one or several cameras, each on the tool or fixed) become sweeps:
// grouped by their stamps into sweep windows, whichever sensor took them.

#include <cstddef>
#include <string>
#include <vector>

#include "cellmap/sweep/sweep_assembler.hpp"

namespace cellmap {

/// Where a frame falls in the stream of sweeps (FrameGrouper::place).
struct FramePlace final {
  bool ends_open_sweep = false;  ///< the open sweep is complete without this frame, which opens the next
  bool completes_sweep = false;  ///< the frame's sweep is complete with it
};

/// Groups posed frames into sweeps as they arrive, so that each frame can be fused at once and the end of
/// its sweep is known as soon as it can be. A sweep spans at most `grouping.period` seconds of frame time
/// from its first frame's stamp: a frame stamped at or after that ends it and opens the next one; a frame
/// stamped earlier (a slower sensor's) joins the open sweep, so no posed frame is lost. A sweep is complete
/// with a frame when every sensor that gave it a frame has reached the window's end: its latest frame plus
/// its frame interval (the time between its last two frames) lies at or past it, so its next frame would
/// open the next sweep anyway; the sweep then ends without waiting for that frame (a frame interval of
/// latency less). A sweep also ends once it holds `grouping.max_frames` frames (0: no limit). Period 0:
/// every frame is a sweep of its own. Holds no frames, only the open sweep's first stamp and the sensors'
/// latest stamps and intervals. Not thread-safe.
class FrameGrouper final {
 public:
  /// @throws Error if the grouping is invalid (SweepParams::validate).
  explicit FrameGrouper(const SweepParams& grouping);

  /// Places a frame of `sensor` stamped `stamp` (seconds) in the stream: whether it ends the open sweep
  /// before it and whether its sweep is complete with it.
  [[nodiscard]] FramePlace place(const std::string& sensor, double stamp);
  /// Ends the open sweep (a sensor stopped streaming; nothing more will end it); false if it held no frame.
  [[nodiscard]] bool flush();
  /// Frames in the open sweep.
  [[nodiscard]] std::size_t open_frames() const { return open_frames_; }

 private:
  struct Sensor {
    std::string name;
    bool seen = false;      // it gave a frame
    double last = 0.0;      // stamp of its latest frame
    double interval = 0.0;  // between its last two frames; 0 = not known yet
    bool in_open = false;   // it gave the open sweep a frame
  };
  Sensor& sensor(const std::string& name);
  static void note_frame(Sensor& sensor, double stamp);
  [[nodiscard]] bool window_reached() const;
  void open(double stamp);

  SweepParams grouping_;
  std::vector<Sensor> sensors_;
  std::size_t open_frames_ = 0;
  double open_first_stamp_ = 0.0;
};

}  // namespace cellmap
