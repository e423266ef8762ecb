#include "health.hpp"

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

Health::Health(std::string cell, std::string sensor_name)
    : cell_(std::move(cell)), sensor_name_(std::move(sensor_name)) {}

void Health::set_sensor(SourceState state, std::string reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  sensor_state_ = state;
  sensor_reason_ = std::move(reason);
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
  const bool sensor_ok = sensor_state_ == SourceState::kClosed || sensor_state_ == SourceState::kConnected;
  if (!sensor_ok) {
    return {DaemonState::kDegraded,
            "sensor '" + sensor_name_ + "': " + sensor_text(sensor_state_, sensor_reason_)};
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
  status.sensors = {{sensor_name_, sensor_text(sensor_state_, sensor_reason_)}};
  status.last_sweep_ns = last_sweep_ns_;
  status.sweeps = sweeps_;
  return status;
}

}  // namespace cellmap::daemon
