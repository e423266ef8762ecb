// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmapd's health as cellmap/status reports it: the daemon's state and why, each sensor's state, the
// sweeps.

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "cellmap/sensor/depth_source.hpp"
#include "cellmap/transport/messages.hpp"

namespace cellmap::daemon {

/// The daemon's state. The status topic carries its name (to_string): a contract with monitoring tools.
enum class DaemonState {
  kStarting,  ///< no sweep processed yet
  kRunning,   ///< sweeps are processed and every version went out
  kDegraded,  ///< something keeps newer content from subscribers or sweeps from the map; the reason says what
  kStopped,   ///< shut down (the last status a clean stop publishes)
};
/// "starting", "running", "degraded", "stopped".
[[nodiscard]] const char* to_string(DaemonState state);

/// The sweep source's state as the status topic shows it: "starting" before it opened (kClosed),
/// "streaming" (kConnected), else the state's name and the reason ("disconnected: openni2: no devices
/// found").
[[nodiscard]] std::string sensor_text(SourceState state, const std::string& reason);

/// What both worker threads report, and the status message made from it. Thread-safe.
///
/// The state is degraded, with the first of these as the reason, while a version could not be saved or
/// published (set_version_fault), while a sensor is not streaming (nothing new of its view reaches the map;
/// the first such sensor in the configured order is named), or after a sweep failed until one succeeds;
/// starting until the first sweep; else running; stopped after stop().
class Health final {
 public:
  /// @param sensor_names  the cell's sensors in the configured order (at least one)
  Health(std::string cell, std::vector<std::string> sensor_names);

  /// Sets the state of sensor `name` (one of the names given). @throws Error for an unknown name.
  void set_sensor(const std::string& name, SourceState state, std::string reason = {});
  /// Sweep `number` (1 for the first) went through the pipeline at `now_ns` (ns since the Unix epoch).
  void sweep_processed(std::uint64_t number, std::int64_t now_ns);
  void sweep_failed(std::string reason);
  /// Why the newest version is not out yet (not saved or not published); empty once it is.
  void set_version_fault(std::string reason);
  void stop();

  /// The state now and the reason for it (empty unless degraded).
  [[nodiscard]] std::pair<DaemonState, std::string> state() const;
  /// cellmap/status without the fields the health does not know (dropped_frames, boxes, version).
  [[nodiscard]] transport::CellStatus status() const;

 private:
  [[nodiscard]] std::pair<DaemonState, std::string> state_locked() const;

  struct Sensor {
    std::string name;
    SourceState state = SourceState::kClosed;
    std::string reason;
  };

  const std::string cell_;
  mutable std::mutex mutex_;
  std::vector<Sensor> sensors_;
  std::string sweep_fault_;
  std::string version_fault_;
  std::int64_t last_sweep_ns_ = 0;
  std::uint64_t sweeps_ = 0;
  bool stopped_ = false;
};

}  // namespace cellmap::daemon
