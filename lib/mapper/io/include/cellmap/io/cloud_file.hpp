// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading point cloud files (PCD, PLY) into the cloud type the stages exchange.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "cellmap/frame/cloud.hpp"

namespace cellmap {

/// Coordinates beyond this magnitude (metres) are taken as a broken file, not as a far point.
inline constexpr double kMaxAbsCoordinate = 1e6;
/// The most points a cloud file may claim (a 4K depth frame has 8.3 million).
inline constexpr std::uint64_t kMaxCloudPoints = 100'000'000;
/// The most bytes a cloud file's points may take as stored (PCL holds them in memory at once).
inline constexpr std::uint64_t kMaxCloudBytes = std::uint64_t{2} << 30;

/// The finite points of one cloud file, in the file's own frame.
struct CloudFile final {
  /// Finite points only (unorganized). `sensor_origin_` carries the file's VIEWPOINT (PCD) so that normals
  /// can be oriented toward the sensor.
  Cloud points;
  /// One label per kept point when the file has a `label` field (e.g. mOSD); empty otherwise.
  std::vector<std::uint32_t> labels;
  /// How many points had a NaN or infinite coordinate and were dropped.
  std::size_t non_finite = 0;
};

struct CloudFileOptions final {
  /// false: a file whose points are all NaN (a frame that saw nothing) loads as an empty cloud.
  bool require_finite_points = true;
};

/// Loads a .pcd or .ply file with PCL's readers. The header is checked by us first and completely (keywords,
/// order, types, counts, and the data its point count needs against the file's size), so that garbage never
/// reaches PCL's parser and nothing is allocated by a header's claims before they are checked; PCL's console
/// output is silenced (library code does not print). Costs one read of the header (at most 64 KiB) on top of
/// PCL's read.
/// Thread safety: safe to call concurrently on different files, except that it lowers PCL's global console
/// verbosity.
/// @throws Error "<file>: <reason>" (one line) if the file is missing, empty, not a PCD/PLY file, has a
/// malformed header, claims more than kMaxCloudPoints points or kMaxCloudBytes bytes or more data than the
/// file holds, has no x/y/z fields (32-bit floats) or a `label` that is not a 32-bit unsigned integer, has no
/// finite point (unless allowed by `options`), or has a coordinate with |value| > kMaxAbsCoordinate.
[[nodiscard]] CloudFile load_cloud_file(const std::filesystem::path& path,
                                        const CloudFileOptions& options = {});

}  // namespace cellmap
