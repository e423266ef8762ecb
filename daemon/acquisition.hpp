// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmapd's acquisition: the frames of the configured sensors (the simulated cell's sweeps, or the cameras'
// posed frames grouped into sweeps as they come) into the frame queue of the thread that fuses them, with
// the ends of the sweeps between them.

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/transport/dds.hpp"
#include "daemon_config.hpp"
#include "frame_queue.hpp"
#include "health.hpp"
#include "input_refusals.hpp"

namespace cellmap::daemon {

/// Where the acquisition thread delivers and reports; shared with the processing thread (all thread-safe).
struct AcquisitionOutput {
  FrameQueue& frames;
  Health& health;
  /// The DDS inputs the source refused (scene edits, robot poses): outside the limits or not applicable.
  InputRefusals& refusals;
  /// The version subscribers have, named in the log lines of a sensor that stops streaming.
  const std::atomic<std::uint64_t>& published_version;
};

/// The cell's sensors, driven by the acquisition thread (which may start a thread per camera).
class Acquisition {
 public:
  virtual ~Acquisition() = default;

  /// Delivers frames and sweep ends into the frame queue and reports the sensor's state to the health until
  /// `stop` is set or, with `max_sweeps` > 0, until that many sweeps were ended or a recording ended before.
  /// Faults it can ride out (a sweep that failed, a camera that went away) are logged and reported, and it
  /// goes on.
  /// @throws std::exception on a fault it cannot ride out: the caller logs it and the daemon degrades.
  virtual void run(const std::atomic<bool>& stop, std::uint64_t max_sweeps) = 0;
  /// For the start log line: "sim (sensor 'kinect', 17 obstacles)", "replay (camera 'wrist')",
  /// "openni2 (camera 'post'), v4l2 (camera 'wrist')".
  [[nodiscard]] virtual std::string describe() const = 0;
  /// The robot model the frames come with (the self filter's): the configured one, or the simulated
  /// scene's; nullopt: frames come without the robot.
  [[nodiscard]] virtual std::optional<Robot> robot() const = 0;
  /// Frames dropped before they made a sweep (without a robot pose or joint sample at their stamp).
  /// Thread-safe.
  [[nodiscard]] virtual std::uint64_t dropped_frames() const { return 0; }
  /// CPU seconds the source's threads used so far (rendering, or reading, decoding and posing frames, and
  /// grouping them). Thread-safe.
  [[nodiscard]] virtual double cpu_seconds() const = 0;
  /// SIGHUP: seconds between sweep starts from the next sweep on; ignored by cameras (their sweep grouping
  /// is fixed when they start). Thread-safe.
  virtual void set_sweep_period(double /*seconds*/) {}
  /// Whether no frame may be dropped (replays played as fast as processed): the source then waits for room
  /// in the frame queue, and so must whoever takes its frames further. Fixed at construction.
  [[nodiscard]] virtual bool lossless() const { return false; }
};

/// The sensors `config.sources` name: the simulated cell, editable over cellmap/sim/scene_edits (edits for
/// `config.cell` or for every cell), or cameras whose tool poses come from their recording or, live, from
/// cellmap/robot_joints through the robot model (`robot` section) or else cellmap/robot_state.
/// `participant` must outlive the result.
/// @throws Error if the source cannot be set up (scene or camera settings invalid, DDS readers refused).
[[nodiscard]] std::unique_ptr<Acquisition> make_acquisition(const DaemonConfig& config,
                                                            const dds::Participant& participant,
                                                            AcquisitionOutput output);

}  // namespace cellmap::daemon
