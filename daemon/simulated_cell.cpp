// SPDX-License-Identifier: Apache-2.0
#include "simulated_cell.hpp"

#include "cellmap/common/error.hpp"
#include "cellmap/sim/default_scene.hpp"

namespace cellmap::daemon {
namespace {

sim::Scene load(const SourceConfig& config) {
  return config.scene.empty() ? sim::default_scene() : sim::load_scene(config.scene.string());
}

std::string scene_name(const SourceConfig& config) {
  return config.scene.empty() ? std::string("default scene") : config.scene.string();
}

// The daemon's model must drive the scene's robot joint by joint.
Robot model_for(const sim::Scene& scene, const std::optional<Robot>& robot, const std::string& name) {
  if (!robot) return scene.robot;
  if (robot->joint_names() != scene.robot.joint_names())
    throw Error("robot: its joints are not those of the robot in " + name);
  return *robot;
}

// Joint samples of a 250 Hz controller over a minute, far more than one sweep window needs.
constexpr std::size_t kSimSamples = 16384;

}  // namespace

DaemonConfig with_scene_workspace(DaemonConfig config) {
  UnknownSpaceConfig& unknown = config.pipeline.unknown;
  if (!unknown.enabled || unknown.workspace || config.sources.empty() || !config.simulated()) return config;
  try {
    unknown.workspace = load(config.sources.front()).workspace;
  } catch (const Error&) {
  }
  return config;
}

SimulatedCell::SimulatedCell(const std::vector<SourceConfig>& sources, const std::optional<Robot>& robot)
    : simulator_(load(sources.front()), sim::SimOptions{sources.front().noise, 2}),
      joints_(model_for(simulator_.scene(), robot, scene_name(sources.front())),
              sources.front().camera.pose_tolerance, kSimSamples) {
  no_return_ranges_.assign(simulator_.scene().sensors.size(), 0.0);
  for (const SourceConfig& source : sources) {
    const int sensor = simulator_.scene().find_sensor(source.sensor);
    if (sensor < 0) throw Error(scene_name(source) + ": no sensor '" + source.sensor + "' (source.sensor)");
    sensors_.push_back(sensor);
    no_return_ranges_[static_cast<std::size_t>(sensor)] = source.no_return_range;
  }
}

FrameSweep SimulatedCell::next_sweep(double start, double duration) {
  ++sweep_index_;
  return simulator_.scene().motion ? moving_sweep(start, duration) : stop_sweep(start);
}

FrameSweep SimulatedCell::moving_sweep(double start, double duration) {
  sim::SimWindow window = simulator_.window(start, start + duration, sensors_);
  for (const JointState& sample : window.joints) joints_.push(sample);
  FrameSweep sweep;
  for (sim::SimFrame& f : window.frames) {
    const JointBuffer::Result robot = joints_.at(f.frame.stamp);
    if (robot.status != PoseLookup::kFound) {
      ++dropped_;
      continue;
    }
    const auto sensor = static_cast<std::size_t>(simulator_.scene().find_sensor(f.frame.sensor));
    const sim::SensorSpec& spec = simulator_.scene().sensors[sensor];
    if (spec.mount == sim::Mount::kTool) f.frame.X_CS = robot.X_CE() * spec.X_ES;
    sweep.stamp = f.frame.stamp;
    sweep.frames.push_back(
        {std::move(f.frame), RobotAt{robot.X_CL, robot.state.payload}, no_return_ranges_[sensor]});
  }
  return sweep;
}

FrameSweep SimulatedCell::stop_sweep(double start) {
  FrameSweep sweep;
  for (const int sensor : sensors_) {
    for (sim::SimFrame& f : simulator_.sweep(sensor, sweep_index_ - 1, start)) {
      RobotAt robot{joints_.robot().link_poses(f.q), std::nullopt};
      sweep.stamp = std::max(sweep.stamp, f.frame.stamp);
      sweep.frames.push_back(
          {std::move(f.frame), std::move(robot), no_return_ranges_[static_cast<std::size_t>(sensor)]});
    }
  }
  return sweep;
}

std::string SimulatedCell::apply(const transport::SceneEdit& edit) {
  return simulator_.apply(edit);
}

std::string SimulatedCell::sensor_names() const {
  std::string names;
  for (const int sensor : sensors_) {
    if (!names.empty()) names += ", ";
    names += simulator_.scene().sensors[static_cast<std::size_t>(sensor)].name;
  }
  return names;
}

double SimulatedCell::pass_duration() const {
  const sim::SweepPlan& plan = simulator_.scene().sweep;
  return plan.period * static_cast<double>(std::max<std::size_t>(plan.stops.size(), 1));
}

}  // namespace cellmap::daemon
