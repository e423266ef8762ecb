// SPDX-License-Identifier: Apache-2.0
#include "daemon.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include "cellmap/common/error.hpp"
#include "cellmap/common/parallel.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "reload.hpp"
#include "simulated_cell.hpp"

namespace cellmap::daemon {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// Once, at start: who may talk to this daemon.
void log_dds_security(const dds::Participant& participant, int domain) {
  const std::optional<security::Credentials>& credentials = participant.credentials();
  if (!credentials) {
    spdlog::warn(
        "DDS Security off: any participant on DDS domain {} can publish scene edits and robot poses to this "
        "daemon and read or forge its environment (see `cellmap security init`)",
        domain);
    return;
  }
  spdlog::info("DDS Security on: {} ({}), credentials valid until {}", credentials->subject,
               credentials->files.certificate.parent_path().string(),
               security::utc_text(credentials->expires));
  const auto left = credentials->expires - std::chrono::system_clock::now();
  if (left < std::chrono::hours(24 * 30)) {
    spdlog::warn(
        "DDS Security: the credentials expire in {} days; issue new ones (docs/security.md, Rotating)",
        std::chrono::duration_cast<std::chrono::hours>(left).count() / 24);
  }
}

// The participant, once its credentials are known to be the cell's own: their permissions grant that cell's
// partition only, so DDS would otherwise refuse the first writer with a reason that names neither cell.
const dds::Participant& of_cell(const dds::Participant& participant, const std::string& cell) {
  const std::optional<security::Credentials>& credentials = participant.credentials();
  if (credentials && credentials->cell != cell) {
    throw Error(credentials->files.certificate.string() + ": issued for cell '" + credentials->cell +
                "', not this daemon's cell '" + cell + "'");
  }
  return participant;
}

// Measures one step on the calling thread.
class Stopwatch {
 public:
  Stopwatch() : wall_(Clock::now()), cpu_(thread_cpu_seconds()) {}
  void add_to(StepCost& cost) const {
    cost.wall += std::chrono::duration<double>(Clock::now() - wall_).count();
    cost.cpu += thread_cpu_seconds() - cpu_;
  }

 private:
  Clock::time_point wall_;
  double cpu_;
};

// The DDS Security setting, once the command line's --security was checked against ROS 2 topics.
const std::optional<security::Setting>& security_of(const DaemonConfig& config) {
  check_ros2_security(config);
  return config.security;
}

std::vector<std::string> sensor_names(const DaemonConfig& config) {
  std::vector<std::string> names;
  for (const SourceConfig& source : config.sources) names.push_back(source.sensor);
  return names;
}

void describe_unknown_space(const UnknownSpaceConfig& unknown) {
  if (!unknown.enabled) {
    spdlog::warn(
        "unknown space off (unknown.enabled: false): planners take space no sensor has seen for free");
  } else if (!unknown.workspace) {
    spdlog::warn(
        "unknown space not tracked: no workspace (set unknown.workspace or segment.workspace); planners take "
        "space no sensor has seen for free");
  } else {
    const Region& w = *unknown.workspace;
    spdlog::info("unknown space tracked in [{}, {}, {}]–[{}, {}, {}] m: pockets from {} m, at most {} boxes",
                 w.min.x(), w.min.y(), w.min.z(), w.max.x(), w.max.y(), w.max.z(), unknown.cover.min_size,
                 unknown.cover.max_boxes);
  }
}

void log_unknown_space(const SweepReport& report, const std::optional<UnknownCover>& cover) {
  if (report.unknown.empty()) return;
  spdlog::info("unknown space: {} added, {} shrunk, {} removed, {} unknown boxes ({:.3f} s)",
               report.unknown.added.size(), report.unknown.modified.size(), report.unknown.removed.size(),
               report.unknown_boxes, report.t_unknown);
  if (!report.unknown_covered || !cover) return;
  spdlog::info(
      "unknown space: {:.2f} of {:.2f} m³ of the workspace never observed ({:.0f} %), {:.2f} m³ of it in "
      "pockets under unknown.min_size left out; the unknown boxes hold {:.2f} m³, {:.2f} m³ of it seen free",
      cover->unknown_volume, cover->grid_volume, 100.0 * cover->unknown_volume / cover->grid_volume,
      cover->ignored_volume, cover->boxed_volume, cover->blocked_free_volume);
}

}  // namespace

Daemon::Daemon(DaemonConfig config, RunOptions options)
    : config_(with_scene_workspace(std::move(config))),
      options_(std::move(options)),
      store_(config_.state_dir, config_.cell),
      participant_(static_cast<std::uint32_t>(config_.domain), security_of(config_)),
      publisher_(of_cell(participant_, config_.cell), config_.cell, config_.delta_depth),
      layers_(participant_, config_.cell),
      ros2_outputs_(config_.ros2, participant_),
      pipeline_(recover_pipeline(config_.pipeline, store_.recovered())),
      keeper_(store_,
              [this](const Environment& env, const EnvironmentDelta& delta) {
                const Stopwatch watch;
                publisher_.publish(env, delta);
                ros2_outputs_.publish(env, delta);
                watch.add_to(publish_cost_);
              }),
      frames_(config_.frame_backlog),
      sweeps_(config_.sweep_backlog),
      health_(config_.cell, sensor_names(config_)),
      refusals_([](const std::string& line) { spdlog::warn("{}", line); }) {
  log_dds_security(participant_, config_.domain);
  keeper_.resume(pipeline_);
  published_version_ = keeper_.published().version();
  acquisition_ = make_acquisition(config_, participant_, {frames_, health_, refusals_, published_version_});
  use_self_filter();
  spdlog::info("cell '{}' on DDS domain {}, state in {}, source {}, version {}", config_.cell, config_.domain,
               store_.directory().string(), acquisition_->describe(), keeper_.published().version());
  if (!ros2_outputs_.describe().empty()) spdlog::info("ROS 2 outputs: {}", ros2_outputs_.describe());
  describe_unknown_space(config_.pipeline.unknown);
}

void Daemon::use_self_filter() {
  const std::optional<Robot> robot = acquisition_->robot();
  const SelfFilterConfig& filter = config_.pipeline.self_filter;
  if (robot) layers_.show_robot(*robot, filter);
  if (!filter.enabled) {
    spdlog::info("self filter off (self_filter.enabled): the robot in view is mapped as an obstacle");
  } else if (!robot) {
    spdlog::warn(
        "self filter off: no robot model (a `robot` section) to cut out of the frames; cameras on the tool "
        "are posed from cellmap/robot_state");
  } else {
    pipeline_.filter_robot(*robot);
    spdlog::info("self filter on: {} links, {} shapes ({} triangles), padding scale {} + {} m",
                 robot->link_names().size(), robot->shapes().size(),
                 pipeline_.self_filter()->triangle_count(), filter.padding_scale, filter.padding);
  }
}

void Daemon::run(const Signals& signals) {
  std::thread acquisition([this] {
    name_this_thread("acquisition");
    acquire();
  });
  std::thread gathering([this] {
    name_this_thread("gathering");
    gather();
  });
  std::thread processing([this] {
    name_this_thread("processing");
    process();
  });
  while (!stop_) {
    const std::optional<int> signal = signals.wait_for(milliseconds(200));
    ros2_outputs_.serve_new_readers();
    if (!signal) continue;
    if (*signal == SIGHUP) {
      const std::optional<double> period =
          reload_config(options_.config_file, config_.simulated(), config_.security);
      if (period) acquisition_->set_sweep_period(*period);
    } else {
      spdlog::info("signal {}: stopping", *signal);
      stop_ = true;
    }
  }
  frames_.close();
  sweeps_.close();
  acquisition.join();
  gathering.join();
  processing.join();
  health_.stop();
  publish_status();
  spdlog::info("stopped at version {}", keeper_.published().version());
}

void Daemon::acquire() {
  try {
    acquisition_->run(stop_, options_.max_sweeps);
    acquisition_done_ = true;
  } catch (const std::exception& e) {
    // Degrade, don't die: the last environment stays published and the status says why.
    spdlog::error("sweep source stopped: {}; keeping version {}", e.what(), published_version_.load());
    for (const SourceConfig& source : config_.sources)
      health_.set_sensor(source.sensor, SourceState::kError, e.what());
  }
}

void Daemon::gather() {
  OpenSweep open = pipeline_.open_sweep();
  for (;;) {
    // Read before take(): a frame put just before acquisition ended is then still taken.
    const bool acquisition_was_done = acquisition_done_;
    std::optional<FrameItem> item = frames_.take(milliseconds(100));
    if (!item) {
      if (stop_ || acquisition_was_done) break;
      continue;
    }
    bool sweep_ended = !item->frame;
    if (item->frame) {
      closed_sweep_first_.wait([this] { return frames_.waiting(); }, frame_backlog_before_gathering(), stop_);
    }
    std::vector<SweepFrame> batch;
    if (item->frame) batch.push_back(std::move(*item->frame));
    // Frames of the same sweep waiting behind it are gathered side by side, a thread each.
    while (!sweep_ended && batch.size() < std::size_t(config_.pipeline.occupancy.threads)) {
      std::optional<FrameItem> next = frames_.take(milliseconds(0));
      if (!next) break;
      sweep_ended = !next->frame;
      if (next->frame) batch.push_back(std::move(*next->frame));
    }
    add_frames(open, std::move(batch));
    if (sweep_ended && open.frames() > 0) hand_over(open.close());
  }
  gathering_done_ = true;
}

void Daemon::add_frames(OpenSweep& open, std::vector<SweepFrame> frames) {
  for (const std::string& fault : open.add(std::move(frames))) {
    health_.sweep_failed(fault);
    ++frame_faults_;
    // At frame rate a fault that persists would flood the log: once a second, with the count.
    if (Clock::now() >= next_frame_fault_log_) {
      spdlog::error("{} ({} frames left out so far); keeping version {}", fault, frame_faults_,
                    published_version_.load());
      next_frame_fault_log_ = Clock::now() + std::chrono::seconds(1);
    }
  }
}

void Daemon::hand_over(GatheredSweep sweep) {
  // A replay played as fast as processed must lose no sweep: wait for the processing thread.
  while (acquisition_->lossless() && !stop_ && !sweeps_.wait_for_room(milliseconds(100))) {
  }
  if (std::optional<GatheredSweep> dropped = sweeps_.put(std::move(sweep)))
    frames_in_dropped_sweeps_ += dropped->frames.frames.size();
}

void Daemon::process() {
  auto next_status = Clock::now();
  std::uint64_t processed = 0;
  for (;;) {
    // Read before take(): a sweep put just before gathering ended is then still taken.
    const bool gathering_was_done = gathering_done_;
    std::optional<GatheredSweep> sweep = sweeps_.take(milliseconds(100));
    if (sweep) {
      handle(*sweep, ++processed);
      if (options_.max_sweeps > 0 && processed >= options_.max_sweeps) stop_ = true;
    } else if (stop_ || gathering_was_done) {
      // With --sweeps, acquisition ends after N sweeps; some may have been dropped on the way, so
      // processing ends when nothing is left to process, not only after N.
      stop_ = true;
      break;
    }
    if (Clock::now() >= next_status) {
      // A version that did not go out is retried here too, so it does not wait for a sweep.
      if (keeper_.pending()) keeper_.flush(pipeline_);
      published_version_ = keeper_.published().version();
      publish_status();
      next_status = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                       std::chrono::duration<double>(config_.status_period));
    }
  }
}

void Daemon::handle(GatheredSweep& sweep, std::uint64_t number) {
  SweepTrace trace;
  trace.number = number;
  trace.sweep = &sweep.frames;
  trace.taken = Clock::now();
  {
    const ClosedSweepFirst::Turn turn(closed_sweep_first_);
    trace.report = run_pipeline(sweep, number);
    publish_version(trace);
  }
  trace.published = Clock::now();
  // The viewer's layers and the map state are not what a planner waits for.
  if (trace.report) layers_.after_sweep(number, sweep.frames, pipeline_.map(), trace.report->changes);
  save_map_state(trace);
  if (!options_.on_sweep) return;
  trace.version = published_version_;
  trace.acquisition_cpu = acquisition_->cpu_seconds();
  options_.on_sweep(trace);
}

std::optional<SweepReport> Daemon::run_pipeline(GatheredSweep& sweep, std::uint64_t number) {
  try {
    SweepReport report = pipeline_.process(sweep);
    health_.sweep_processed(number, wall_clock_ns());
    spdlog::info(
        "sweep {}: {} frames, {} points, {} on the robot, {} hit / {} free voxels, {} flipped, {} change "
        "regions, {} boxes; self filter {:.3f} s, fuse {:.3f} s (map update {:.3f} s), change {:.3f} s, "
        "segment {:.3f} s; {} sweeps dropped, {} frames dropped",
        number, report.frames, report.points, report.robot_points, report.hit_voxels, report.free_voxels,
        report.flipped, report.regions, report.boxes, report.t_filter, report.t_fuse, report.t_update,
        report.t_change, report.t_segment, sweeps_.dropped(), dropped_frames());
    log_unknown_space(report, pipeline_.unknown_cover());
    return report;
  } catch (const Error& e) {
    health_.sweep_failed("sweep " + std::to_string(number) + ": " + e.what());
    spdlog::error("sweep {}: {}; keeping version {}", number, e.what(), keeper_.published().version());
    return std::nullopt;
  }
}

void Daemon::publish_version(SweepTrace& trace) {
  publish_cost_ = {};
  const Stopwatch boxes;
  keeper_.publish_boxes(pipeline_);
  boxes.add_to(trace.persist);
  trace.persist.wall -= publish_cost_.wall;
  trace.persist.cpu -= publish_cost_.cpu;
  trace.publish = publish_cost_;
  published_version_ = keeper_.published().version();
}

void Daemon::save_map_state(SweepTrace& trace) {
  const Stopwatch map_state;
  keeper_.save_map_state(pipeline_);
  map_state.add_to(trace.map_state);
}

std::size_t Daemon::frame_backlog_before_gathering() const {
  return std::max<std::size_t>(1, config_.frame_backlog / 4);
}

std::uint64_t Daemon::dropped_frames() const {
  return frames_.dropped() + frames_in_dropped_sweeps_ + acquisition_->dropped_frames();
}

void Daemon::publish_status() {
  health_.set_version_fault(keeper_.fault());
  transport::CellStatus status = health_.status();
  status.dropped_frames = dropped_frames();
  status.boxes = keeper_.published().boxes().size();
  status.version = keeper_.published().version();
  status.refused_inputs = refusals_.count();
  try {
    publisher_.publish_status(status);
    status_fault_.clear();
  } catch (const Error& e) {
    if (status_fault_ != e.what()) spdlog::warn("status not published: {}", e.what());
    status_fault_ = e.what();
  }
}

}  // namespace cellmap::daemon
