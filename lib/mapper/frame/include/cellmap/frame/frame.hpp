// SPDX-License-Identifier: Apache-2.0
#pragma once
// One sensor frame and the depth-image → points conversion every camera source shares.

#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/common/field_of_view.hpp"
#include "cellmap/frame/cloud.hpp"

namespace cellmap {

/// Pinhole camera model of a depth image. Sensor frame S: x right, y down, z forward (optical axis), metres.
struct PinholeIntrinsics final {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0;       ///< focal lengths, pixels
  double cx = 0, cy = 0;       ///< principal point, pixels
  double depth_scale = 0.001;  ///< metres per raw depth unit (1 mm for Kinect-class and RealSense Z16)
  double min_range = 0.0;      ///< depths below this (metres along z) are treated as no return
  double max_range = 10.0;     ///< depths above this are treated as no return
  /// Flying-pixel filter: a pixel lying behind a valid 8-neighbour by more than this share of its own depth
  /// is treated as no return. At a depth edge a camera's pixel mixes the near and the far surface (time of
  /// flight) or smears one into the other (stereo) and its depth lands in between, in free space behind the
  /// near surface's rim; such points are not measurements of a surface (what PCL calls veil or shadow
  /// points). The near rim stays (it is the object's outline); the price is the far surface's rim (one
  /// pixel) and surfaces seen within about atan(pixel angle / max_depth_jump) of grazing (Kinect v2 at
  /// 256 × 212, 0.31° pixels: 0.02 → 15°), which other views see. 0 = off (the default here; every
  /// configured camera sets its own, see docs/config.md).
  double max_depth_jump = 0.0;
  /// Depth smoothing of stereo cameras, pixels: each depth becomes the mean of the depths within this many
  /// pixels along its row, then along its column, that lie within max_depth_jump of it (edge-preserving:
  /// needs max_depth_jump > 0). Active stereo matching scatters a flat surface's depths by a few centimetres
  /// (more with z²); fused at a 2 cm voxel, occupied wins, that scatter makes the surface several voxels
  /// thick. 0 = off (the default here; RealSense-class cameras set 2, see docs/config.md).
  int smoothing_radius = 0;

  /// @throws Error if a size or focal length is not positive, the range is empty, max_depth_jump negative or
  /// smoothing_radius outside [0, kMaxSmoothingRadius].
  void validate() const;
};

/// max_depth_jump of a configured camera unless its configuration says otherwise: time-of-flight and
/// structured-light cameras (Kinect v2, PS1080)...
inline constexpr double kDefaultMaxDepthJump = 0.02;
/// ... and active stereo cameras (RealSense D4xx), whose depth noise grows with z² (neighbours differ by
/// several centimetres at 3 m without any edge).
inline constexpr double kStereoMaxDepthJump = 0.05;

/// smoothing_radius of a configured stereo camera unless its configuration says otherwise, and the largest.
inline constexpr int kStereoSmoothingRadius = 2;
inline constexpr int kMaxSmoothingRadius = 16;

/// A raw 16-bit depth image, row-major, `depth.size() == width * height`; 0 means no return.
struct DepthImage final {
  PinholeIntrinsics intrinsics;
  std::vector<std::uint16_t> depth;
};

/// Back-projects a depth image into the sensor frame: p_S = ((u - cx) z / fx, (v - cy) z / fy, z), leaving
/// out pixels without a return, outside [min_range, max_range] or on a depth edge (max_depth_jump), after
/// smoothing the depths (smoothing_radius).
/// With `organized`, the cloud keeps width × height with NaN for pixels without a valid return (matches PCL's
/// grabbers); otherwise only valid points are returned. @throws Error if the image size disagrees with the
/// intrinsics or the intrinsics are invalid.
[[nodiscard]] Cloud depth_to_points(const DepthImage& image, bool organized = false);

/// One frame of one sensor, with the pose it was taken from.
struct Frame final {
  std::string sensor;                                      ///< sensor name from the configuration
  double stamp = 0.0;                                      ///< seconds (sensor clock or simulated time)
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();  ///< sensor pose in the cell frame at `stamp`
  std::optional<DepthImage> depth;                         ///< cameras only
  Cloud points_S;  ///< valid points in the sensor frame (from `depth`, or a scanner's scan)
  /// Line scanners: a point at the far end of each beam that saw nothing within its range, in the sensor
  /// frame (a camera's such pixels are the 0s of `depth`). SweepFrame::no_return_range clears along them.
  Cloud no_return_S;
  /// What the sensor could see, set by sources that know it without a depth image (line scanners).
  std::optional<FieldOfView> field_of_view;
};

/// A pinhole camera's frustum: the rays through the outer corners of the image (pixel edges, not
/// centres), closed, out to max_range. @throws Error if the intrinsics are invalid.
[[nodiscard]] FieldOfView frustum(const PinholeIntrinsics& intrinsics);

/// What the sensor of `frame` could see: its field_of_view, else the frustum of its depth image, else none.
[[nodiscard]] std::optional<FieldOfView> field_of_view(const Frame& frame);

}  // namespace cellmap
