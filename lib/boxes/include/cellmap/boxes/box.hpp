// SPDX-License-Identifier: Apache-2.0
#pragma once
// The collision box: what segmentation produces, environments version and planners check against.

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace cellmap {

/// The space a box stands for: an obstacle box holds occupied space, an unknown box space no sensor has
/// observed. A planner treats both as blocked by default (docs/environment.md#unknown-space).
enum class BoxSpace : std::uint8_t {
  kOccupied = 0,  ///< fitted to occupied voxels: something is there (an obstacle box)
  kUnknown = 1,   ///< covers workspace no sensor has observed: something may be there (an unknown box)
};

/// "occupied" or "unknown": the name in the boxes JSON, logs and docs.
[[nodiscard]] const char* space_name(BoxSpace space);

/// An oriented box in the cell frame C (metres). `rotation` is R_CB, the box axes expressed in C; an
/// axis-aligned box has the identity rotation. Plain value type; a default Box is a degenerate point at the
/// origin with id 0.
struct Box final {
  std::uint64_t id = 0;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();        ///< p_CB, metres
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();  ///< along the box's own x, y, z axes, metres, >= 0
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  ///< R_CB, unit quaternion
  /// How many input points the box was fitted to; for an unknown box, the unknown voxels it covers.
  std::uint64_t points = 0;
  BoxSpace space = BoxSpace::kOccupied;

  /// True when p_C lies inside the box grown by `tolerance` on every side.
  [[nodiscard]] bool contains(const Eigen::Vector3d& p_C, double tolerance = 0.0) const;
  [[nodiscard]] double volume() const { return 8.0 * half_extents.prod(); }
  [[nodiscard]] bool is_axis_aligned() const;
};

/// The colour of a box wherever cellmap shows it (the view, `cellmap render`, RViz markers), RGB 0–1: a hue
/// from the id, so a box keeps its colour from version to version.
[[nodiscard]] std::array<double, 3> box_colour(std::uint64_t id);
/// The colour of every unknown box, RGB 0–1: a neutral grey no obstacle hue comes near (box_colour keeps
/// saturation 0.5).
inline constexpr std::array<double, 3> kUnknownColour = {0.55, 0.55, 0.55};

/// A set of boxes with the version and frame they belong to: the boxes JSON file (docs/boxes-json.md).
struct BoxSet final {
  std::uint64_t version = 0;
  std::string frame = "cell";
  std::vector<Box> boxes;
};

/// Serialises to the boxes JSON contract: {"version", "frame", "boxes": [{"id", "center", "half_extents",
/// "rotation" [w,x,y,z], "points", "space"}]}; "space" is written for unknown boxes only ("unknown"), so a
/// file of obstacle boxes reads as it did before unknown boxes existed. Numbers keep full double precision.
[[nodiscard]] std::string to_json(const BoxSet& set);

/// Parses the boxes JSON contract; a box without "space" holds occupied space. @throws Error naming `source`
/// and the offending field on malformed input, non-finite numbers, negative half extents, a non-unit
/// quaternion or a space other than "occupied" or "unknown".
[[nodiscard]] BoxSet box_set_from_json(const std::string& text, const std::string& source = "boxes");

/// Writes the boxes file atomically (see write_file_atomically). @throws Error on I/O failure.
void write_box_file(const std::filesystem::path& path, const BoxSet& set);
/// Reads a boxes file. @throws Error on I/O failure or malformed content.
[[nodiscard]] BoxSet read_box_file(const std::filesystem::path& path);

}  // namespace cellmap
