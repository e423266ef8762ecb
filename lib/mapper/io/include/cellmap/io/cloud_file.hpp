#pragma once
// Reading point cloud files (PCD, PLY) into the cloud type the stages exchange.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "cellmap/frame/cloud.hpp"

namespace cellmap {

/// Coordinates beyond this magnitude (metres) are taken as a broken file, not as a far point.
inline constexpr double kMaxAbsCoordinate = 1e6;

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

/// Loads a .pcd or .ply file with PCL's readers. The header is checked by us first, so that garbage never
/// reaches PCL's parser; PCL's console output is silenced (library code does not print).
/// Thread safety: safe to call concurrently on different files, except that it lowers PCL's global console
/// verbosity.
/// @throws Error "<file>: <reason>" if the file is missing, empty, not a PCD/PLY file, has no x/y/z fields,
/// has no finite point, or has a coordinate with |value| > kMaxAbsCoordinate.
[[nodiscard]] CloudFile load_cloud_file(const std::filesystem::path& path);

}  // namespace cellmap
