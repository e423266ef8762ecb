// SPDX-License-Identifier: Apache-2.0
#pragma once
// The self filter: a frame's measurements of the robot itself (its links' collision shapes at the frame's
// joint state, and the payload it holds) are removed before fusion, so the robot never becomes an obstacle.
// A measurement on the robot turns into a clear-only ray (Scan::clear_C) that clears free space up to the
// robot's padded near surface and stops there: free space in front of the robot is still cleared, and what
// the robot hides stays as it was in the map.
//
// Padding and latency. Joint samples and frames are stamped on one clock; the robot is posed at the frame's
// stamp from the bracketing joint samples (JointBuffer). Any error in those stamps (controller delay not
// compensated, camera exposure time, clock offset) places the rendered robot where it was up to `latency`
// seconds earlier or later, so a surface point moving at speed v (m/s, the fastest point of the robot in
// view: usually the tool or the payload's far corner) is off by v · latency. The padding offset must cover
// that, the sensor's depth noise at the robot's distance and the geometry's calibration error:
//   padding ≥ v · latency + depth noise bound(z) + calibration.
// The latency term: 0.5 m/s × 20 ms = 1 cm; 1 m/s × 20 ms = 2 cm; 2 m/s × 20 ms = 4 cm; 1 m/s × 50 ms = 5 cm.
// The noise term (the simulator's hard bounds): Kinect v2 3 σ with σ = 1 mm + 0.5 mm/m² · z², 2 cm at 3.4 m;
// RealSense D435 at 640 × 480 4.5 σ (waviness included) with σ = 4.2 mm/m² · z², 1.9 cm at 1 m, 4.2 cm at
// 1.5 m, 7.5 cm at 2 m (stereo: keep the robot near it or pad more). The default offset, 4 cm, is 2 cm of motion (1 m/s × 20 ms) plus a Kinect v2's
// noise at 3.4 m. A measurement that the noise puts in front of the padded surface stays a hit; so do depth
// pixels that the sensor mixed with a nearer surface beside the robot (time-of-flight flying pixels, stereo
// smear), which nothing tells apart from an object in front of the robot. `padding_scale` grows every shape
// about its centre on top (for models that are systematically too small).

#include <Eigen/Geometry>

#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "cellmap/config/yaml_map.hpp"
#include "cellmap/frame/frame.hpp"
#include "cellmap/robot/joint_state.hpp"
#include "cellmap/robot/robot.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap {

/// How the robot is grown before it is cut out of the frames (YAML section `self_filter`).
struct SelfFilterConfig final {
  /// Off: frames pass unchanged (filter() equals to_scan) (`self_filter.enabled`).
  bool enabled = true;
  /// Every shape scaled about its centre by this factor, ≥ 1 (`self_filter.padding_scale`): boxes' half
  /// extents, cylinders' radius and half length, spheres' radius; meshes about the centre of their bounds.
  double padding_scale = 1.0;
  /// Metres added on every side after scaling, in [0, 1] (`self_filter.padding`): boxes' half extents,
  /// cylinders' radius and half length, spheres' radius grow by it; mesh vertices move outwards along their
  /// vertex normals so that every face moves out by at least this much. See the header comment for the
  /// padding a given stamp latency needs.
  double padding = 0.04;

  /// @throws Error naming the field ("self_filter.padding: ...") if a value is out of range.
  void validate() const;
  /// Reads the `self_filter` section (absent keys keep their defaults). Keys: enabled, padding_scale,
  /// padding. @throws Error naming the key for unknown keys, wrong types or bad ranges.
  [[nodiscard]] static SelfFilterConfig from_yaml(YamlMap section);
};

/// The robot at one instant, in the cell frame: what JointBuffer::at() returns for a frame's stamp.
struct RobotAt final {
  std::vector<Eigen::Isometry3d> X_CL;  ///< every link's pose, in Robot::link_names() order
  std::optional<Payload> payload;       ///< what the tool (the last link) holds, if anything
};

/// What filtering one frame did.
struct SelfFilterResult final {
  /// The frame's valid points in the cell frame (as to_scan) without the ones on the robot, and one
  /// clear-only ray end (Scan::clear_C) per removed point.
  Scan scan;
  std::size_t kept = 0;     ///< points kept as hits
  std::size_t removed = 0;  ///< points on (or behind) the padded robot, now clear-only rays
  /// Shapes not used in this frame because the sensor origin lies inside them once padded (a wrist camera
  /// inside its tool's padding would otherwise lose every point); see SelfFilter::filter.
  std::size_t skipped_shapes = 0;
};

/// Cuts one robot out of sensor frames. Built once per robot and configuration: shapes are padded and
/// primitives tessellated at construction.
/// Immutable afterwards; filter() is const and may run on several threads at once (each call allocates its
/// own depth buffer).
class SelfFilter final {
 public:
  /// @throws Error if `config` is invalid. A robot without shapes gives a filter that removes nothing.
  SelfFilter(const Robot& robot, const SelfFilterConfig& config);
  ~SelfFilter();
  SelfFilter(SelfFilter&&) noexcept;
  SelfFilter& operator=(SelfFilter&&) noexcept;

  /// Filters `frame` (points_S in the sensor frame, X_CS set) with the robot at `robot` (normally the robot
  /// at frame.stamp). Cameras (frame.depth present: only its intrinsics are read, the image may be empty) use
  /// a depth buffer: the padded shapes are rasterized (pixel centres, as depth_to_points back-projects) and
  /// a point whose depth z is at or behind the buffer's depth at its pixel is on the robot. Other sensors
  /// (line scanners: no depth image) test each point's ray against the padded shapes; a point at or beyond
  /// the ray's first entry into a shape is on the robot. A removed point's clear-only ray ends where its
  /// line of sight meets the padded robot. Non-finite points are dropped (as to_scan). A shape whose padded
  /// form contains the sensor origin (meshes: their padded bounds) is skipped for this frame and counted.
  /// With enabled = false, returns to_scan(frame) with every point kept.
  /// @throws Error if robot.X_CL does not hold one pose per link of the robot, or the intrinsics are invalid.
  [[nodiscard]] SelfFilterResult filter(const Frame& frame, const RobotAt& robot) const;

  [[nodiscard]] const SelfFilterConfig& config() const;
  /// Triangles rendered per frame for the whole robot without payload (meshes plus tessellated primitives).
  [[nodiscard]] std::size_t triangle_count() const;

 private:
  struct Model;
  std::unique_ptr<const Model> model_;
};

}  // namespace cellmap
