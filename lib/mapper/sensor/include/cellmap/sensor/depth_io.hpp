// SPDX-License-Identifier: Apache-2.0
#pragma once
// Depth images on disk: 16-bit PNG and TIFF, and the intrinsics files that go with them.

#include <cstdint>
#include <string>
#include <vector>

#include "cellmap/frame/frame.hpp"

namespace cellmap {

/// A single-channel 16-bit image as stored: raw sensor units, row-major, width × height values.
struct RawDepth final {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> depth;
};

/// Reads a single-channel 16-bit grayscale PNG (libpng) or TIFF (libtiff), chosen by the extension (.png,
/// .tif, .tiff; any case). Values are returned as stored (PNG's big-endian samples are converted to host
/// order).
/// @throws Error naming the file if it cannot be read, is not one channel of 16 bits, claims more than
/// kMaxDepthPixels pixels, or the extension is unknown.
[[nodiscard]] RawDepth read_depth_image(const std::string& path);
/// The most pixels a depth image read from disk may have: 2²⁴ (4096 × 4096, 32 MB), 18 times the largest
/// depth camera mode cellmap knows of (RealSense 1280 × 720). A header of a few bytes can claim any size,
/// and the image is allocated before its rows are read.
inline constexpr std::uint64_t kMaxDepthPixels = std::uint64_t{1} << 24;

/// Writes a single-channel 16-bit grayscale PNG (the replay directory's depth format), crash-safely (through
/// a temporary file renamed over `path`). @throws Error naming the file if the size disagrees or writing
/// fails.
void write_depth_png(const std::string& path, const RawDepth& image);

/// Reads the `<depth>` block of a PCL grabber intrinsics file (focal_length_x/y, principal_point_x/y,
/// z_multiplication_factor) with PCL's own reader (pcl::io::LZFDepth16ImageReader::readParameters). Width and
/// height are not in the file: they are left 0 for the caller to fill from the image.
/// @throws Error naming the file if it cannot be read or lacks the depth parameters.
[[nodiscard]] PinholeIntrinsics read_pcl_intrinsics_xml(const std::string& path);

/// Reads intrinsics from a YAML map with keys width, height, fx, fy, cx, cy, depth_scale (default 0.001),
/// min_range (default 0), max_range (default 10), max_depth_jump (default kDefaultMaxDepthJump; 0 = off),
/// smoothing_radius (default 0 = off); unknown keys are refused.
/// @throws Error naming the file and key on a missing, unknown or invalid value.
[[nodiscard]] PinholeIntrinsics read_intrinsics_yaml(const std::string& path);

}  // namespace cellmap
