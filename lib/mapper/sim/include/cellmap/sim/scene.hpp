// SPDX-License-Identifier: Apache-2.0
#pragma once
// The simulated cell: its bounds, the obstacles in it, the robot, the sensors (on the robot or fixed), the
// sweep plan, and what moves while frames are taken (the robot's motion, walkers).
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "cellmap/common/region.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/frame/frame.hpp"
#include "cellmap/robot/robot.hpp"
#include "cellmap/sim/motion.hpp"

namespace cellmap::sim {

// The primitive shapes are the robot's (cellmap/robot/geometry.hpp), also reachable as sim::BoxShape etc.
using cellmap::BoxShape;
using cellmap::CylinderShape;
using cellmap::SphereShape;

/// An obstacle's solid, in the obstacle's frame O.
using Shape = std::variant<BoxShape, CylinderShape, SphereShape>;

/// One named solid obstacle of the scene. X_CO is the pose of the shape's frame O in the cell frame.
struct Obstacle final {
  std::string name;
  Shape shape = BoxShape{};
  Eigen::Isometry3d X_CO = Eigen::Isometry3d::Identity();

  /// Volume of the solid, m³.
  [[nodiscard]] double volume() const;
  /// Area of the solid's surface, m².
  [[nodiscard]] double surface_area() const;
  /// Signed distance from p_C to the surface: negative inside, positive outside, metres (exact for all three
  /// shapes).
  [[nodiscard]] double signed_distance(const Eigen::Vector3d& p_C) const;
  /// Radius of a sphere about the frame origin that contains the solid, metres.
  [[nodiscard]] double bounding_radius() const;
  /// Points on the surface about `spacing` apart (a regular grid per face / ring), in the cell frame.
  /// Used as the ground truth of "the obstacle's surface" by tests and the sensor comparison.
  [[nodiscard]] std::vector<Eigen::Vector3d> sample_surface(double spacing) const;
};

/// The paper's three sensors. Cameras render a DepthImage; the OS32C is a 2D line scanner.
enum class SensorModel { kKinectV2, kRealsenseD435, kOs32c };

/// "kinect_v2", "realsense_d435", "os32c".
[[nodiscard]] std::string to_string(SensorModel model);
/// @throws Error listing the known names if `name` is none of them.
[[nodiscard]] SensorModel sensor_model_from_string(const std::string& name);

/// A 2D line scanner: beams in the x–y plane of its frame S, at angles from -fov/2 to +fov/2 about +z
/// measured from +x (the ROS LaserScan convention), evenly spaced, first and last beam included.
struct LineScanner final {
  double fov = 4.71238898038469;    ///< radians (270°)
  int beams = 676;                  ///< 0.4° steps over 270°
  double min_range = 0.05;          ///< metres
  double max_range = 10.0;          ///< metres
  double range_resolution = 0.001;  ///< ranges are reported in these steps, metres

  /// @throws Error if a value is out of its range.
  void validate() const;
  /// The fan: beams from the first to the last at most 30° apart (open), out to max_range.
  [[nodiscard]] FieldOfView field_of_view() const;
};

/// The stops of one sweep: robot joint vectors visited in order, one frame per stop, `period` seconds apart.
struct SweepPlan final {
  std::vector<Eigen::VectorXd> stops;
  double period = 0.1;
};

/// Where a sensor is mounted: on the robot's tool (posed through the robot) or fixed in the cell.
enum class Mount { kTool, kCell };

/// Where a sensor sits: on the tool at X_ES, or fixed in the cell at X_CS (the other pose unused).
struct SensorMount final {
  Mount mount = Mount::kTool;
  Eigen::Isometry3d X_ES = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
};

/// Reads a sensor's mount from the map holding it, the one mount schema of scenes and cellmapd's sources:
/// `mount: tool` or `mount: cell` with `pose: {position, rotation}` (X_ES or X_CS), or `mount: {position,
/// rotation}` (X_ES on the tool); neither key: on the tool at identity. @throws Error naming the key.
[[nodiscard]] SensorMount read_mount(YamlMap& map);

/// One sensor, on the end-effector E with the hand-eye extrinsic X_ES, or fixed in the cell at X_CS.
struct SensorSpec final {
  std::string name;
  SensorModel model = SensorModel::kKinectV2;
  Mount mount = Mount::kTool;
  Eigen::Isometry3d X_ES = Eigen::Isometry3d::Identity();  ///< on the tool
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();  ///< fixed in the cell
  PinholeIntrinsics intrinsics;                            ///< cameras only
  LineScanner scanner;                                     ///< line scanners only
  std::uint64_t seed = 1;                                  ///< noise seed; same seed → same frames
  std::optional<SweepPlan> sweep;  ///< overrides the scene's plan (a line scanner needs dense stops)

  [[nodiscard]] bool is_camera() const { return model != SensorModel::kOs32c; }
};

/// The native depth mode of a camera model (Kinect v2: 512×424, fx 365; RealSense D435: 640×480, fx 383; both
/// 1 mm depth units), with its documented working range.
/// @throws Error for a model that is not a camera.
[[nodiscard]] PinholeIntrinsics default_intrinsics(SensorModel model);

/// A complete simulated cell. Plain value type; build it with load_scene/parse_scene or by hand and call
/// validate().
struct Scene final {
  Region cell;
  std::vector<Obstacle> obstacles;
  Robot robot;
  std::vector<SensorSpec> sensors;
  SweepPlan sweep;
  std::optional<Motion>
      motion;  ///< the robot moving all the time (Simulator::window); none: sweeps stop by stop
  std::vector<Walker> walkers;  ///< people walking through while the robot moves
  /// Where unknown space matters in this cell (`workspace: {lower, upper}`): cellmapd's `unknown.workspace`
  /// when its config names none. None: the daemon's config decides.
  std::optional<Region> workspace;

  /// The plan `sensor` follows: its own, or the scene's.
  [[nodiscard]] const SweepPlan& plan_for(const SensorSpec& sensor) const;
  /// Index of the obstacle named `name`, or -1.
  [[nodiscard]] int find_obstacle(const std::string& name) const;
  /// Index of the sensor whose name, or else whose model name, is `name`; -1 if none.
  [[nodiscard]] int find_sensor(const std::string& name) const;
  /// X_CS of sensor `index` at joint vector q: X_CE(q) · X_ES on the tool, X_CS when fixed.
  /// @throws Error as Robot::tool_pose.
  [[nodiscard]] Eigen::Isometry3d sensor_pose(int index, const Eigen::VectorXd& q) const;

  /// Checks what parse_scene checks, for scenes built by hand or edited: bounds non-empty, obstacle names
  /// unique and non-empty, sizes positive, sensors valid, every stop within the robot's limits and every
  /// sensor inside the cell at every stop of its plan, the motion and walkers valid, every picked obstacle a
  /// box.
  /// @throws Error naming the obstacle, sensor, stop, waypoint or walker.
  void validate() const;
};

/// `scene` with every camera's depth filters off (PinholeIntrinsics::max_depth_jump and smoothing_radius 0):
/// the exact sweep of that scene is the whole surface its cameras see, what a filtered sweep's boxes are
/// scored against.
[[nodiscard]] Scene without_depth_filter(Scene scene);

/// Reads the `robot` section of a scene (or daemon) file: `gantry: {lower, upper, tool_at_zero, [bridge,
/// carriage, ram: {center, half_extents}]}` (parts at q = 0 in the cell frame; default GantryParts::fitting)
/// or `urdf: {file, tool_link, [base], [package_paths]}` (relative paths against `base_dir`; the URDF's
/// collision geometry and meshes are loaded). @throws Error naming the key.
[[nodiscard]] Robot read_robot(YamlMap map, const std::string& base_dir);

/// Reads a scene file (format: config/cell.yaml, documented there). A URDF path is relative to the file.
/// @throws Error "<file>: <key path>: <reason>" for unknown keys, wrong types, non-positive sizes, a stop
/// outside the robot's limits, or a sensor outside the cell at a stop.
[[nodiscard]] Scene load_scene(const std::string& file);
/// As load_scene, on YAML text; `source` names it in messages and `base_dir` resolves relative paths.
[[nodiscard]] Scene parse_scene(const std::string& yaml, const std::string& source,
                                const std::string& base_dir = ".");

}  // namespace cellmap::sim
