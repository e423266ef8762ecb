#include "simulated_cell.hpp"

#include "cellmap/common/error.hpp"
#include "cellmap/sim/default_scene.hpp"

namespace cellmap::daemon {
namespace {

sim::Scene load(const SourceConfig& config) {
  return config.scene.empty() ? sim::default_scene() : sim::load_scene(config.scene.string());
}

}  // namespace

SimulatedCell::SimulatedCell(const SourceConfig& config)
    : simulator_(load(config), sim::SimOptions{config.noise, 2}) {
  sensor_ = simulator_.scene().find_sensor(config.sensor);
  if (sensor_ < 0) {
    throw Error((config.scene.empty() ? std::string("default scene") : config.scene.string()) +
                ": no sensor '" + config.sensor + "' (source.sensor)");
  }
  sensor_name_ = config.sensor;
}

Sweep SimulatedCell::next_sweep(double start_stamp) {
  std::vector<Frame> frames;
  for (sim::SimFrame& f : simulator_.sweep(sensor_, sweep_index_++, start_stamp))
    frames.push_back(std::move(f.frame));
  return merge_frames(frames);
}

std::string SimulatedCell::apply(const transport::SceneEdit& edit) {
  return simulator_.apply(edit);
}

}  // namespace cellmap::daemon
