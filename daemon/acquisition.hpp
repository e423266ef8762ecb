#pragma once
// cellmapd's acquisition thread: sweeps from the configured source (the simulated cell, or one camera's posed
// frames grouped into sweeps) into the processing thread's latest-wins mailbox.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "cellmap/sweep/sweep.hpp"
#include "cellmap/transport/dds.hpp"
#include "daemon_config.hpp"
#include "health.hpp"
#include "input_refusals.hpp"
#include "latest_mailbox.hpp"

namespace cellmap::daemon {

/// Where the acquisition thread delivers and reports; shared with the processing thread (all thread-safe).
struct AcquisitionOutput {
  LatestMailbox<Sweep>& mailbox;
  Health& health;
  /// The DDS inputs the source refused (scene edits, robot poses): outside the limits or not applicable.
  InputRefusals& refusals;
  /// The version subscribers have, named in the log lines of a sensor that stops streaming.
  const std::atomic<std::uint64_t>& published_version;
};

/// One sweep source, driven by the acquisition thread.
class Acquisition {
 public:
  virtual ~Acquisition() = default;

  /// Delivers sweeps into the mailbox and reports the sensor's state to the health until `stop` is set or,
  /// with `max_sweeps` > 0, until that many sweeps were delivered or a recording ended before. Faults it can
  /// ride out (a sweep that failed, a camera that went away) are logged and reported, and it goes on.
  /// @throws std::exception on a fault it cannot ride out: the caller logs it and the daemon degrades.
  virtual void run(const std::atomic<bool>& stop, std::uint64_t max_sweeps) = 0;
  /// For the start log line: "sim (sensor 'kinect', 17 obstacles)", "replay (camera 'wrist')".
  [[nodiscard]] virtual std::string describe() const = 0;
  /// Frames the source dropped before they made a sweep (a camera's frames without a robot pose).
  /// Thread-safe.
  [[nodiscard]] virtual std::uint64_t dropped_frames() const { return 0; }
  /// SIGHUP: seconds between sweep starts from the next sweep on; ignored by cameras (their sweep grouping
  /// is fixed when they start). Thread-safe.
  virtual void set_sweep_period(double /*seconds*/) {}
};

/// The source `config.source` names: the simulated cell, editable over cellmap/sim/scene_edits (edits for
/// `config.cell` or for every cell), or a camera whose tool poses come from its recording or, live, from
/// cellmap/robot_state. `participant` must outlive the result.
/// @throws Error if the source cannot be set up (scene or camera settings invalid, DDS readers refused).
[[nodiscard]] std::unique_ptr<Acquisition> make_acquisition(const DaemonConfig& config,
                                                            const dds::Participant& participant,
                                                            AcquisitionOutput output);

}  // namespace cellmap::daemon
