// SPDX-License-Identifier: Apache-2.0
#pragma once
// Free-space evidence from camera pixels without a return (SweepFrame::no_return_range): internal to the cell
// pipeline.

#include <cstddef>

#include "cellmap/frame/frame.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap {

/// Adds to `scan.clear_C` one clear-only ray end, `range` metres from the sensor along the pixel's line of
/// sight (cell frame), for the pixels of `frame.depth` without a return (raw 0) in every other row and
/// column: of each 2 × 2 block of pixels the one `phase` (0–3; taken modulo 4) picks, so four frames with
/// phases 0 to 3 use every pixel at a quarter of the rays each. A line scanner's frame adds one ray per beam
/// of its no_return_S, ending at `range` or the beam's end, whichever is nearer. Frames with neither (cameras
/// that dropped their image) add nothing. Returns the rays added.
std::size_t add_no_return_rays(const Frame& frame, double range, unsigned phase, Scan& scan);

}  // namespace cellmap
