// SPDX-License-Identifier: Apache-2.0
#pragma once
// The simulated sensors: frames rendered by ray casting the scene from the robot's sensor poses.

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "cellmap/frame/frame.hpp"
#include "cellmap/sim/noise.hpp"
#include "cellmap/sim/ray_cast.hpp"
#include "cellmap/sim/scene.hpp"
#include "cellmap/sim/scene_edit.hpp"

namespace cellmap::sim {

struct SimOptions final {
  bool noise = true;         ///< false: zero-noise mode (exact depths, only quantized to the depth unit)
  int threads = 2;           ///< threads casting one camera frame (rows are split between them)
  bool render_robot = true;  ///< false: the robot's collision shapes and payload are invisible
};

/// One simulated frame with the ground truth behind it.
struct SimFrame final {
  Frame frame;        ///< exactly what a real source delivers (cameras: depth + points_S; scanners: points_S)
  Eigen::VectorXd q;  ///< the joint vector the frame was taken at
  /// Per pixel (row-major) or per beam: exact depth along the optical axis (cameras) or range (scanners) of
  /// the first surface, metres, before noise and quantization; 0 = no return (nothing within range in the
  /// cell).
  std::vector<double> exact;
  /// Per pixel or beam: index of the obstacle the exact ray hit, RayHit::kRobot (-2) = the robot or its
  /// payload, RayHit::kNothing (-1) = none.
  std::vector<int> hit;
};

/// The moving cell at one instant: the robot's true joint state (with what it carries) and the obstacles
/// (picked boxes gone, placed ones where they were put, walkers where they are).
struct CellState final {
  JointState robot;
  std::vector<Obstacle> obstacles;
};

/// What the moving cell produces in a stretch of time: frames of every sensor and the controller's joint
/// samples, each sorted by stamp. A frame's `hit` indexes state_at(its stamp).obstacles.
struct SimWindow final {
  std::vector<SimFrame> frames;
  std::vector<JointState> joints;
};

/// Renders frames of a scene. Returns are deterministic: the same scene, options, sensor, stop, sweep and
/// frame index give bit-identical frames. render() and sweep() are const and may run concurrently; apply()
/// must not run concurrently with them.
class Simulator final {
 public:
  /// @throws Error if the scene does not validate.
  explicit Simulator(Scene scene, SimOptions options = {});

  [[nodiscard]] const Scene& scene() const { return scene_; }
  [[nodiscard]] const SimOptions& options() const { return options_; }

  /// Applies a scene edit (see sim::apply) for the following frames. @throws Error as sim::apply.
  std::string apply(const transport::SceneEdit& edit);

  /// One frame of sensor `sensor` (index into scene().sensors) with the robot at `state` (stamped
  /// state.stamp): the robot's collision shapes and payload are rendered (unless options().render_robot is
  /// false) and a sensor on the tool is posed by them. Rays are cast through pixel centres (pixel (u, v)
  /// looks along ((u − cx)/fx, (v − cy)/fy, 1)) or along the scanner's beams. Depths outside [min_range,
  /// max_range] and points that would lie outside the cell give no return (no walls are modelled: what is
  /// beyond the cell bounds is not seen). Camera depths are rounded to the depth unit.
  /// @throws Error if `sensor` is out of range or the state is invalid for the robot.
  [[nodiscard]] SimFrame render(int sensor, const JointState& state, std::uint64_t sweep_index,
                                std::uint64_t frame_index) const;
  /// As above with nothing in the tool: render(sensor, {stamp, q, none}, ...).
  [[nodiscard]] SimFrame render(int sensor, const Eigen::VectorXd& q, double stamp, std::uint64_t sweep_index,
                                std::uint64_t frame_index) const;

  /// The cell at time t (seconds from the motion's start): the robot at the scene's motion (without one: at
  /// the first stop of the sweep plan), pick and place and walkers applied.
  [[nodiscard]] CellState state_at(double t) const;

  /// The moving cell in [t0, t1): every sensor takes a frame at each multiple k of its plan's period in the
  /// window (stamp = capture time t; noise keyed by k, so a window repeats bit for bit), rendered with
  /// state_at(t); the controller reports a joint sample at each multiple of 1 / controller_rate in the
  /// window, stamped t + joint_stamp_delay, with its payload. What a daemon's simulated source needs: fuse
  /// the frames, feed the joint samples to its joint buffer. `sensors` (indices into scene().sensors) limits
  /// the frames to those sensors; empty: every sensor. @throws Error if t1 < t0 or t0 < 0, or a sensor index
  /// is out of range.
  [[nodiscard]] SimWindow window(double t0, double t1, const std::vector<int>& sensors = {}) const;

  /// All frames of one sweep of `sensor` along its plan: frame k at stop k, stamp start + k·period.
  /// `sweep_index` keys the noise, so successive sweeps see fresh noise and a repeated index repeats it.
  [[nodiscard]] std::vector<SimFrame> sweep(int sensor, std::uint64_t sweep_index = 0,
                                            double start_stamp = 0.0) const;

 private:
  [[nodiscard]] SimFrame render_in(int sensor, const JointState& state,
                                   const std::vector<Obstacle>& obstacles, const NoiseKey& key) const;
  [[nodiscard]] SimFrame render_camera(const SensorSpec& spec, const Eigen::Isometry3d& X_CS,
                                       const NoiseKey& key, const SceneCaster& caster) const;
  [[nodiscard]] SimFrame render_scanner(const SensorSpec& spec, const Eigen::Isometry3d& X_CS,
                                        const NoiseKey& key, const SceneCaster& caster) const;

  Scene scene_;
  SimOptions options_;
  SceneCaster caster_;  // the obstacles alone
  RobotSolids robot_solids_;
  struct Carry {  // a box the motion picks (and places)
    std::string name;
    double pick_time = 0, place_time = 0;  // place_time: infinity while never placed
    Payload payload;
    Obstacle placed;
  };
  std::vector<Carry> carries_;  // the robot's shapes, meshes with their trees
};

}  // namespace cellmap::sim
