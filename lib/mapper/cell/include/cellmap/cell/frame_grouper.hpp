#pragma once
// How the posed frames of a cell's sensors (one or several cameras, each on the tool or fixed) become sweeps:
// grouped by their stamps into sweep windows, whichever sensor took them.

#include <cstddef>

#include "cellmap/sweep/sweep_assembler.hpp"

namespace cellmap {

/// Where a frame falls in the stream of sweeps (FrameGrouper::place).
struct FramePlace final {
  bool ends_open_sweep = false;  ///< the open sweep is complete without this frame, which opens the next
  bool completes_sweep = false;  ///< the frame's sweep is complete with it (`grouping.max_frames` reached)
};

/// Groups posed frames into sweeps as they arrive, so that each frame can be fused at once and the end of
/// its sweep is known when it comes. A sweep spans at most `grouping.period` seconds of frame time from its
/// first frame's stamp: a frame stamped at or after that ends it and opens the next one; a frame stamped
/// earlier (a slower sensor's) joins the open sweep, so no posed frame is lost. A sweep also ends once it
/// holds `grouping.max_frames` frames (0: no limit). Period 0: every frame is a sweep of its own, ended when
/// the next one arrives or at flush(). Holds no frames, only the open sweep's first stamp and frame count.
/// Not thread-safe.
class FrameGrouper final {
 public:
  /// @throws Error if the grouping is invalid (SweepParams::validate).
  explicit FrameGrouper(const SweepParams& grouping);

  /// Places a frame stamped `stamp` (seconds) in the stream: whether it ends the open sweep before it and
  /// whether its sweep is complete with it.
  [[nodiscard]] FramePlace place(double stamp);
  /// Ends the open sweep (a sensor stopped streaming; nothing more will end it); false if it held no frame.
  [[nodiscard]] bool flush();
  /// Frames in the open sweep.
  [[nodiscard]] std::size_t open_frames() const { return open_frames_; }

 private:
  SweepParams grouping_;
  std::size_t open_frames_ = 0;
  double open_first_stamp_ = 0.0;
};

}  // namespace cellmap
