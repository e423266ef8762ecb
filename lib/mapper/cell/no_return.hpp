#pragma once
// Free-space evidence from camera pixels without a return (SweepFrame::no_return_range): internal to the cell
// pipeline.

#include <cstddef>

#include "cellmap/frame/frame.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap {

/// Adds to `scan.clear_C` one clear-only ray end, `range` metres from the sensor along the pixel's line of
/// sight (cell frame), for every pixel of `frame.depth` without a return (raw 0). Frames without a depth
/// image (line scanners, cameras that dropped it) add nothing. Returns the rays added.
std::size_t add_no_return_rays(const Frame& frame, double range, Scan& scan);

}  // namespace cellmap
