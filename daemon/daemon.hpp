// SPDX-License-Identifier: Apache-2.0
#pragma once
// cellmapd's wiring: the state directory, the cell pipeline, DDS, the sweep source and the threads.
//
// Threads: acquisition (frames and sweep ends from the source → a bounded frame queue), gathering (each frame
// cut by the self filter and its observed voxels gathered into its sweep as it arrives → a bounded backlog of
// gathered sweeps, oldest taken first), processing (map update, change detection, re-segmentation → version
// kept, saved and published → status), and the caller's (signals: SIGTERM/SIGINT stop, SIGHUP reloads).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "acquisition.hpp"
#include "bounded_mailbox.hpp"
#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/environment/version_store.hpp"
#include "cellmap/transport/environment_publisher.hpp"
#include "closed_sweep_first.hpp"
#include "daemon_config.hpp"
#include "frame_queue.hpp"
#include "health.hpp"
#include "input_refusals.hpp"
#include "layer_publisher.hpp"
#include "ros2_outputs.hpp"
#include "signals.hpp"
#include "versions.hpp"

namespace cellmap::daemon {

/// Seconds one step took: wall time, and CPU time of the thread that ran it.
struct StepCost {
  double wall = 0.0;
  double cpu = 0.0;
};

/// One sweep the processing thread handled, for measuring the daemon (`cellmap bench daemon`).
struct SweepTrace {
  std::uint64_t number = 0;           ///< sweeps handled so far, this one included
  const FrameSweep* sweep = nullptr;  ///< the sweep's frames (without points); valid during the call only
  std::optional<SweepReport> report;  ///< what the pipeline did; nullopt if the sweep failed
  StepCost persist;                   ///< saving the version the sweep made (its boxes), if it made one
  StepCost publish;                   ///< publishing it (snapshot and delta)
  StepCost map_state;                 ///< saving the map state with it, after publishing
  std::chrono::steady_clock::time_point taken;      ///< when the processing thread took the sweep
  std::chrono::steady_clock::time_point published;  ///< when its version went out (or it was done with)
  std::uint64_t version = 0;                        ///< the version subscribers have after the sweep
  double acquisition_cpu = 0.0;                     ///< CPU seconds the sweep source's threads used so far
};

/// What the command line adds to the config.
struct RunOptions {
  std::filesystem::path config_file;  ///< re-read on SIGHUP; empty = the built-in defaults
  std::uint64_t max_sweeps = 0;       ///< stop after this many sweeps (0 = until SIGTERM/SIGINT)
  /// Called on the processing thread after each sweep was handled and its version went out; must return
  /// quickly. Empty = none.
  std::function<void(const SweepTrace&)> on_sweep;
};

class Daemon final {
 public:
  /// Opens the state directory, recovers the pipeline, joins the DDS domain, announces the recovered version
  /// and sets up the sweep source. @throws Error if any of that fails (the state directory of another cell,
  /// an invalid scene, DDS refused).
  Daemon(DaemonConfig config, RunOptions options);

  /// Runs until a stop signal (or, with max_sweeps, until the sweeps are processed); then publishes the
  /// status `stopped`.
  void run(const Signals& signals);

 private:
  void acquire();
  void gather();
  // Adds frames to the open sweep; a frame that fails is logged, reported and left out.
  void add_frames(OpenSweep& open, std::vector<SweepFrame> frames);
  // Hands the gathered sweep to the processing thread (waiting for room if the source is lossless).
  void hand_over(GatheredSweep sweep);
  void process();
  void handle(GatheredSweep& sweep, std::uint64_t number);
  // Runs the pipeline on the sweep and logs what it did; nullopt if the sweep failed (logged, reported).
  std::optional<SweepReport> run_pipeline(GatheredSweep& sweep, std::uint64_t number);
  // Frames of the next sweep that may wait while a closed sweep is processed: a quarter of the frame queue
  // (a version's usual processing lets a frame or two of each camera wait), so that a long processing (the
  // first segmentation of a cell) drops none.
  [[nodiscard]] std::size_t frame_backlog_before_gathering() const;
  // Frames never fused: dropped from the frame queue, in sweeps dropped from the backlog, or by the source.
  [[nodiscard]] std::uint64_t dropped_frames() const;
  // Saves and publishes the version the sweep made, if it made one (VersionKeeper::publish_boxes), its cost
  // split into saving the boxes and publishing.
  void publish_version(SweepTrace& trace);
  // Saves the map state with the version (VersionKeeper::save_map_state).
  void save_map_state(SweepTrace& trace);
  // Gives the pipeline the acquisition's robot model to cut out of the frames (self_filter.enabled), and the
  // robot layer the model to show.
  void use_self_filter();
  void publish_status();

  DaemonConfig config_;
  RunOptions options_;
  VersionStore store_;
  dds::Participant participant_;
  transport::EnvironmentPublisher publisher_;
  LayerPublisher layers_;     // the optional layers, written only while a viewer reads them
  Ros2Outputs ros2_outputs_;  // MoveIt and RViz, when the config enables them
  CellPipeline pipeline_;
  VersionKeeper keeper_;
  FrameQueue frames_;
  BoundedMailbox<GatheredSweep> sweeps_;
  ClosedSweepFirst closed_sweep_first_;  // frames of the next sweep wait while a closed one is processed
  std::atomic<std::uint64_t> frames_in_dropped_sweeps_{0};
  std::uint64_t frame_faults_ = 0;  // frames that failed to fuse (gathering thread)
  std::chrono::steady_clock::time_point next_frame_fault_log_;  // gathering thread
  Health health_;
  InputRefusals refusals_;
  std::atomic<std::uint64_t> published_version_{0};  // for the acquisition and gathering threads' log lines
  std::unique_ptr<Acquisition> acquisition_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> acquisition_done_{false};
  std::atomic<bool> gathering_done_{false};
  std::string status_fault_;  // the last reason a status was not published, logged once
  StepCost publish_cost_;     // of the publications during the current publish_version()
};

}  // namespace cellmap::daemon
