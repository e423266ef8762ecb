#pragma once
// The simulated sweep source of cellmapd: the simulator's scene, swept with one of its sensors, editable
// between sweeps through cellmap/sim/scene_edits.

#include <cstdint>
#include <string>

#include "cellmap/sim/simulator.hpp"
#include "cellmap/sweep/sweep.hpp"
#include "cellmap/transport/messages.hpp"
#include "daemon_config.hpp"

namespace cellmap::daemon {

/// Renders sweeps of the configured scene and applies scene edits between them. Not thread-safe: the
/// acquisition thread owns it.
class SimulatedCell final {
 public:
  /// @throws Error naming the scene file or the sensor when the scene does not load or has no such sensor.
  explicit SimulatedCell(const SourceConfig& config);

  /// The next sweep along the scene's sweep plan, in the cell frame; fresh noise each call.
  [[nodiscard]] Sweep next_sweep(double start_stamp);
  /// Applies an edit received over DDS; returns the obstacle's name. @throws Error if the edit is invalid
  /// (unknown name, taken name, bad size); the scene is then unchanged.
  std::string apply(const transport::SceneEdit& edit);

  [[nodiscard]] const sim::Scene& scene() const { return simulator_.scene(); }
  [[nodiscard]] const std::string& sensor_name() const { return sensor_name_; }

 private:
  sim::Simulator simulator_;
  int sensor_ = 0;
  std::string sensor_name_;
  std::uint64_t sweep_index_ = 0;
};

}  // namespace cellmap::daemon
