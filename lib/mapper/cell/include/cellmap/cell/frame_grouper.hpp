#pragma once
// How the posed frames of a cell's sensors (one or several cameras, each on the tool or fixed) become sweeps:
// grouped by their stamps into sweep windows, whichever sensor took them.

#include <cstddef>
#include <optional>
#include <vector>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/sweep/sweep_assembler.hpp"

namespace cellmap {

/// Groups posed frames into sweeps. A sweep spans at most `grouping.period` seconds of frame time from its
/// first frame's stamp: a frame stamped at or after that closes it and opens the next one; a frame stamped
/// earlier (a slower sensor's) joins the open sweep, so no posed frame is lost. A sweep also closes once it
/// holds `grouping.max_frames` frames (0: no limit). Period 0: every frame is its own sweep, handed out when
/// the next one arrives or at flush(). Frames keep their order of arrival. Not thread-safe.
class FrameGrouper final {
 public:
  /// @throws Error if the grouping is invalid (SweepParams::validate).
  explicit FrameGrouper(const SweepParams& grouping);

  /// Adds a posed frame; returns the sweeps it closed (none, one, or two with max_frames 1), oldest first.
  [[nodiscard]] std::vector<FrameSweep> add(SweepFrame frame);
  /// Hands out the open sweep, if it holds a frame (a sensor stopped streaming; nothing more will close it).
  [[nodiscard]] std::optional<FrameSweep> flush();
  /// Frames in the open sweep.
  [[nodiscard]] std::size_t open_frames() const { return open_.frames.size(); }

 private:
  SweepParams grouping_;
  FrameSweep open_;
  double open_first_stamp_ = 0.0;
};

}  // namespace cellmap
