// SPDX-License-Identifier: Apache-2.0
#include "health.hpp"

#include "cellmap/common/error.hpp"

namespace cellmap::daemon {

const char* to_string(DaemonState state) {
  switch (state) {
    case DaemonState::kStarting:
      return "starting";
    case DaemonState::kRunning:
      return "running";
    case DaemonState::kDegraded:
      return "degraded";
    case DaemonState::kStopped:
      return "stopped";
  }
  return "?";
}

std::string sensor_text(SourceState state, const std::string& reason) {
  if (state == SourceState::kClosed) return "starting";
  if (state == SourceState::kConnected) return "streaming";
  std::string text = to_string(state);
  if (!reason.empty()) text += ": " + reason;
  return text;
}

Health::Health(std::string cell, std::vector<std::string> sensor_names) : cell_(std::move(cell)) {
  for (std::string& name : sensor_names) sensors_.push_back({std::move(name), SourceState::kClosed, {}});
}

void Health::set_sensor(const std::string& name, SourceState state, std::string reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (Sensor& sensor : sensors_) {
    if (sensor.name != name) continue;
    sensor.state = state;
    sensor.reason = std::move(reason);
    return;
  }
  throw Error("health: no sensor '" + name + "'");
}

void Health::sweep_processed(std::uint64_t number, std::int64_t now_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  sweeps_ = number;
  last_sweep_ns_ = now_ns;
  sweep_fault_.clear();
}

void Health::sweep_failed(std::string reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  sweep_fault_ = std::move(reason);
}

void Health::set_version_fault(std::string reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  version_fault_ = std::move(reason);
}

void Health::stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  stopped_ = true;
}

std::pair<DaemonState, std::string> Health::state() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_locked();
}

std::pair<DaemonState, std::string> Health::state_locked() const {
  if (stopped_) return {DaemonState::kStopped, ""};
  if (!version_fault_.empty()) return {DaemonState::kDegraded, version_fault_};
  for (const Sensor& sensor : sensors_) {
    if (sensor.state == SourceState::kClosed || sensor.state == SourceState::kConnected) continue;
    return {DaemonState::kDegraded,
            "sensor '" + sensor.name + "': " + sensor_text(sensor.state, sensor.reason)};
  }
  if (!sweep_fault_.empty()) return {DaemonState::kDegraded, sweep_fault_};
  return {sweeps_ == 0 ? DaemonState::kStarting : DaemonState::kRunning, ""};
}

transport::CellStatus Health::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  transport::CellStatus status;
  status.cell = cell_;
  const auto [state, reason] = state_locked();
  status.state = to_string(state);
  status.reason = reason;
  for (const Sensor& sensor : sensors_)
    status.sensors.push_back({sensor.name, sensor_text(sensor.state, sensor.reason)});
  status.last_sweep_ns = last_sweep_ns_;
  status.sweeps = sweeps_;
  return status;
}

}  // namespace cellmap::daemon
