// cellmapd: keeps one cell's collision environment up to date and publishes its versions over DDS.
//
// Threads: acquisition (sweeps from the source — the simulated cell, or a camera's posed frames grouped into
// sweeps — → a latest-wins mailbox), processing (fusion → change → re-segmentation → version → persist →
// publish, plus status), and main (signals).
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <iostream>
#include <mutex>
#include <thread>

#include "camera_input.hpp"
#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/environment/version_store.hpp"
#include "cellmap/transport/environment_publisher.hpp"
#include "cellmap/transport/scene_edits.hpp"
#include "daemon_config.hpp"
#include "latest_mailbox.hpp"
#include "signals.hpp"
#include "simulated_cell.hpp"

namespace cellmap::daemon {
namespace {

using Clock = std::chrono::steady_clock;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// What the status topic reports; written by both worker threads.
struct Health {
  std::mutex mutex;
  std::string state = "starting";
  std::string sensor_state = "starting";
  std::int64_t last_sweep_ns = 0;
  std::uint64_t sweeps = 0;
};

struct Options {
  std::string config_file;
  std::optional<int> domain;
  std::optional<std::string> state_dir;
  std::uint64_t max_sweeps = 0;
};

class Daemon {
 public:
  Daemon(DaemonConfig config, const Options& options)
      : config_(std::move(config)),
        options_(options),
        store_(config_.state_dir, config_.cell),
        participant_(static_cast<std::uint32_t>(config_.domain)),
        publisher_(participant_, config_.cell, config_.delta_depth),
        current_(config_.cell),
        sweep_period_(config_.sweep_period) {
    const RecoveredState& recovered = store_.recovered();
    for (const std::string& problem : recovered.problems) spdlog::warn("state: {}", problem);
    std::optional<std::string> map_state;
    if (recovered.blob) {
      try {
        map_state = read_file(*recovered.blob);
      } catch (const Error& e) {
        spdlog::warn("state: {}; starting with an empty map", e.what());
      }
    }
    const std::vector<Box>& boxes = recovered.environment.boxes();
    const std::uint64_t next_id = recovered.next_box_id;
    try {
      pipeline_.emplace(config_.pipeline, boxes, next_id, map_state);
    } catch (const Error& e) {
      spdlog::warn("state: {}; starting with an empty map", e.what());
      pipeline_.emplace(config_.pipeline, boxes, next_id);
    }
    current_ = recovered.environment;
    if (current_.version() > 0) resume();
    current_version_ = current_.version();
    if (config_.source.is_camera()) {
      camera_.emplace(config_.source, participant_, config_.cell);
      const auto* replay = std::get_if<ReplayConfig>(&config_.source.camera.source);
      lossless_ = replay && replay->playback == ReplayConfig::Playback::kFastest;
      spdlog::info("cell '{}' on DDS domain {}, state in {}, source {} (camera '{}'), version {}",
                   config_.cell, config_.domain, store_.directory().string(), config_.source.kind,
                   camera_->name(), current_.version());
    } else {
      sim_.emplace(config_.source);
      edits_.emplace(participant_);
      spdlog::info(
          "cell '{}' on DDS domain {}, state in {}, source sim (sensor '{}', {} obstacles), version {}",
          config_.cell, config_.domain, store_.directory().string(), sim_->sensor_name(),
          sim_->scene().obstacles.size(), current_.version());
    }
  }

  void run(const Signals& signals) {
    std::thread acquisition([this] {
      try {
        acquire();
        acquisition_done_ = true;
      } catch (const std::exception& e) {
        // Degrade, don't die: the last environment stays published and the status says why.
        spdlog::error("sweep source stopped: {}; keeping version {}", e.what(), current_version_.load());
        set_sensor_state(std::string("error: ") + e.what());
      }
    });
    std::thread processing([this] { process(); });
    while (!stop_) {
      const std::optional<int> signal = signals.wait_for(std::chrono::milliseconds(200));
      if (!signal) continue;
      if (*signal == SIGHUP) {
        reload();
      } else {
        spdlog::info("signal {}: stopping", *signal);
        stop_ = true;
      }
    }
    mailbox_.close();
    acquisition.join();
    processing.join();
    publish_status("stopped");
    spdlog::info("stopped at version {}", current_.version());
  }

 private:
  // A restart resumes at the persisted version (VersionStore::resume() says under which number).
  void resume() {
    current_ = store_.resume(now_ns(), pipeline_->map_state());
    publisher_.publish(current_);
    spdlog::info("resumed version {} with {} boxes", current_.version(), current_.boxes().size());
  }

  void reload() {
    try {
      const DaemonConfig fresh = DaemonConfig::load(options_.config_file);
      spdlog::set_level(spdlog::level::from_str(fresh.log_level));
      if (camera_) {  // a camera's sweep grouping is fixed when it starts
        spdlog::info("SIGHUP: reloaded log_level={} (other keys apply at restart)", fresh.log_level);
        return;
      }
      sweep_period_ = fresh.sweep_period;
      spdlog::info("SIGHUP: reloaded log_level={} sweep_period={} s (other keys apply at restart)",
                   fresh.log_level, fresh.sweep_period);
    } catch (const Error& e) {
      spdlog::error("SIGHUP: config not reloaded: {}", e.what());
    }
  }

  void acquire() {
    if (camera_) {
      acquire_camera();
    } else {
      acquire_sim();
    }
  }

  // Sweeps come as the camera's frames arrive and get their poses; the camera's own back-off paces retries.
  void acquire_camera() {
    const SourceStatus opened = camera_->open();
    std::string reported = camera_->sensor_state();
    if (opened.state == SourceState::kConnected) {
      spdlog::info("camera '{}': {}", camera_->name(), reported);
    } else {
      spdlog::warn("camera '{}': {}", camera_->name(), reported);
    }
    set_sensor_state(reported);
    if (opened.state == SourceState::kConnected && camera_->poses_received() > 0)
      spdlog::info("camera '{}': {} recorded robot poses", camera_->name(), camera_->poses_received());
    std::uint64_t dropped_reported = 0;
    auto next_drop_log = Clock::now();
    while (!stop_) {
      std::vector<Sweep> sweeps;
      try {
        sweeps = camera_->step(std::chrono::milliseconds(100));
      } catch (const Error& e) {
        spdlog::error("camera '{}': {}", camera_->name(), e.what());
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      for (Sweep& sweep : sweeps) {
        // A replay played as fast as processed must lose no sweep: wait for the processing thread.
        while (lossless_ && !stop_ && !mailbox_.wait_taken(std::chrono::milliseconds(100))) {
        }
        mailbox_.put(std::move(sweep));
        if (options_.max_sweeps > 0 && ++acquired_ >= options_.max_sweeps) return;
      }
      // --sweeps N on a recording shorter than N sweeps ends with the recording (its last sweep was flushed).
      if (options_.max_sweeps > 0 && camera_->status().state == SourceState::kEnded) return;
      camera_dropped_ = camera_->dropped_frames();
      const std::string state = camera_->sensor_state();
      if (state != reported) {
        if (state == "streaming") {
          spdlog::info("camera '{}': streaming", camera_->name());
        } else {
          spdlog::warn("camera '{}': {}; keeping version {}", camera_->name(), state,
                       current_version_.load());
        }
        set_sensor_state(state);
        reported = state;
      }
      if (camera_->dropped_frames() > dropped_reported && Clock::now() >= next_drop_log) {
        spdlog::warn(
            "camera '{}': {} frames dropped without a robot pose within {} s ({} poses received, {} "
            "malformed)",
            camera_->name(), camera_->dropped_frames(), config_.source.camera.pose_tolerance,
            camera_->poses_received(), camera_->poses_rejected());
        dropped_reported = camera_->dropped_frames();
        next_drop_log = Clock::now() + std::chrono::seconds(1);
      }
    }
  }

  void acquire_sim() {
    double stamp = 0.0;
    while (!stop_) {
      const auto start = Clock::now();
      try {
        for (const transport::SceneEdit& edit : edits_->take()) {
          if (!edit.cell.empty() && edit.cell != config_.cell) continue;
          try {
            spdlog::info("scene edit applied: {}", sim_->apply(edit));
          } catch (const Error& e) {
            spdlog::warn("scene edit rejected: {}", e.what());
          }
        }
        Sweep sweep = sim_->next_sweep(stamp);
        stamp += sweep_period_;
        mailbox_.put(std::move(sweep));
        set_sensor_state("streaming");
      } catch (const Error& e) {
        set_sensor_state(std::string("error: ") + e.what());
        spdlog::error("sweep source: {}", e.what());
      }
      if (options_.max_sweeps > 0 && ++acquired_ >= options_.max_sweeps) break;
      const auto next = start + seconds(sweep_period_.load());
      while (!stop_ && Clock::now() < next) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  void process() {
    auto next_status = Clock::now();
    std::uint64_t processed = 0;
    for (;;) {
      // Read before take(): a sweep put just before acquisition ended is then still taken.
      const bool acquisition_was_done = acquisition_done_;
      std::optional<Sweep> sweep = mailbox_.take(std::chrono::milliseconds(100));
      if (sweep) {
        handle(*sweep, ++processed);
        if (options_.max_sweeps > 0 && processed >= options_.max_sweeps) stop_ = true;
      } else if (stop_ || acquisition_was_done) {
        // With --sweeps, acquisition ends after N sweeps; some may have been replaced in the mailbox, so
        // processing ends when the mailbox is empty, not only after N.
        stop_ = true;
        break;
      }
      if (Clock::now() >= next_status) {
        publish_status(state());
        next_status = Clock::now() + seconds(config_.status_period);
      }
    }
  }

  void handle(const Sweep& sweep, std::uint64_t number) {
    try {
      SweepReport report = pipeline_->process(sweep);
      {
        std::lock_guard<std::mutex> lock(health_.mutex);
        health_.state = "running";
        health_.last_sweep_ns = now_ns();
        health_.sweeps = number;
      }
      spdlog::info(
          "sweep {}: {} points, {} hit / {} free voxels, {} flipped, {} change regions, {} boxes; "
          "fuse {:.3f} s, change {:.3f} s, segment {:.3f} s; {} sweeps dropped",
          number, report.points, report.hit_voxels, report.free_voxels, report.flipped, report.regions,
          report.boxes, report.t_fuse, report.t_change, report.t_segment, mailbox_.dropped());
      if (report.change) publish_version(*report.change);
    } catch (const Error& e) {
      std::lock_guard<std::mutex> lock(health_.mutex);
      health_.state = "degraded";
      spdlog::error("sweep {}: {}; keeping version {}", number, e.what(), current_.version());
    }
  }

  // Persist first, then publish: a number subscribers saw is always on disk (never reused after a crash).
  void publish_version(const Reconciled& change) {
    const Environment next(config_.cell, store_.next_version(), now_ns(), pipeline_->boxes());
    const EnvironmentDelta delta = diff(current_, next);
    store_.save(next, pipeline_->map_state(), pipeline_->next_box_id());
    publisher_.publish(next, delta);
    current_ = next;
    current_version_ = next.version();
    spdlog::info("version {}: {} added, {} modified, {} removed, {} boxes", next.version(),
                 change.added.size(), change.modified.size(), change.removed.size(), next.boxes().size());
  }

  // Degraded while the sensor is not streaming, whatever the last sweep did: no version comes from it.
  std::string state() {
    std::lock_guard<std::mutex> lock(health_.mutex);
    if (health_.sensor_state != "streaming" && health_.sensor_state != "starting") return "degraded";
    return health_.state;
  }

  void set_sensor_state(const std::string& sensor_state) {
    std::lock_guard<std::mutex> lock(health_.mutex);
    health_.sensor_state = sensor_state;
  }

  void publish_status(const std::string& state) {
    transport::CellStatus status;
    {
      std::lock_guard<std::mutex> lock(health_.mutex);
      status.cell = config_.cell;
      status.state = state;
      status.sensors = {{camera_ ? camera_->name() : sim_->sensor_name(), health_.sensor_state}};
      status.last_sweep_ns = health_.last_sweep_ns;
      status.sweeps = health_.sweeps;
    }
    // Sweeps the processing thread had no time for, plus camera frames that had no robot pose.
    status.dropped_frames = mailbox_.dropped() + (camera_ ? camera_dropped_.load() : 0);
    status.boxes = current_.boxes().size();
    status.version = current_.version();
    try {
      publisher_.publish_status(status);
    } catch (const Error& e) {
      spdlog::warn("status not published: {}", e.what());
    }
  }

  DaemonConfig config_;
  Options options_;
  VersionStore store_;
  dds::Participant participant_;
  transport::EnvironmentPublisher publisher_;
  std::optional<transport::SceneEditReader> edits_;  // sim only
  std::optional<SimulatedCell> sim_;                 // sim only
  std::optional<CameraInput> camera_;                // cameras only
  bool lossless_ = false;  // a replay played as fast as processed: no sweep is replaced in the mailbox
  std::optional<CellPipeline> pipeline_;
  Environment current_;
  LatestMailbox<Sweep> mailbox_;
  Health health_;
  std::atomic<bool> stop_{false};
  std::atomic<double> sweep_period_;
  std::uint64_t acquired_ = 0;
  std::atomic<bool> acquisition_done_{false};
  std::atomic<std::uint64_t> current_version_{0};  // for the acquisition thread's log lines
  std::atomic<std::uint64_t> camera_dropped_{0};   // the camera's frames dropped without a pose
};

}  // namespace
}  // namespace cellmap::daemon

int main(int argc, char** argv) {
  using namespace cellmap::daemon;
  CLI::App app{"cellmapd: keeps a robot cell's collision environment up to date and publishes it over DDS"};
  Options options;
  int domain = 0;
  std::string state_dir;
  app.add_option("--config", options.config_file,
                 "YAML config (default: built-in defaults, the simulated cell)")
      ->check(CLI::ExistingFile);
  auto* domain_option =
      app.add_option("--domain", domain, "DDS domain id (overrides the config)")->check(CLI::Range(0, 232));
  auto* state_option = app.add_option("--state-dir", state_dir, "state directory (overrides the config)");
  app.add_option("--sweeps", options.max_sweeps, "stop after this many sweeps (0 = run until SIGTERM)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "cellmapd: " << e.what() << " (see cellmapd --help)\n";
    return 2;
  }
  if (*domain_option) options.domain = domain;
  if (*state_option) options.state_dir = state_dir;

  spdlog::set_default_logger(spdlog::stderr_color_mt("cellmapd"));
  spdlog::set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ %v");
  try {
    // Signals are blocked before any thread starts, so only the main thread takes them.
    const Signals signals;
    cellmap::daemon::DaemonConfig config = options.config_file.empty()
                                               ? DaemonConfig::parse("", "defaults", ".")
                                               : DaemonConfig::load(options.config_file);
    if (options.domain) config.domain = *options.domain;
    if (options.state_dir) config.state_dir = *options.state_dir;
    spdlog::set_level(spdlog::level::from_str(config.log_level));
    Daemon daemon(std::move(config), options);
    daemon.run(signals);
  } catch (const cellmap::Error& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
  return 0;
}
