// SPDX-License-Identifier: Apache-2.0
// cellmap bench daemon: the whole daemon path fed with two native cameras of the default cell at frame rate.
//
// Two replay recordings of the default cell's cameras on the gantry's tool, in their native modes (Kinect v2
// 512 × 424 with no_return_range 4.5 m, it is a time-of-flight camera; RealSense D435 848 × 480), rendered
// at start with the cameras' noise: the gantry goes back and forth over the table, and a crate appears on
// the table and goes again every --change-every seconds after a warm-up. cellmapd's own wiring (Daemon: the
// camera threads, sweep grouping, the latest-wins mailbox, the cell pipeline, the version keeper saving to
// a state directory, DDS publication) plays them at their recorded speed, and a subscriber process (the
// planner client library) follows the cell on loopback.
//
// Reports frames fused per second per camera, frames dropped (played but never fused), CPU per frame by
// stage, and the latency from the frame that confirmed a change (the last frame of the sweep that made a
// version, at the time its camera delivered it) to the version's arrival at the subscriber. The anchor of
// the ratio line: OctoMap's discretized insertPointCloud on frames of the same recordings, CPU per frame.
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/cell/frame_grouper.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/research/evaluate.hpp"
#include "cellmap/sensor/depth_io.hpp"
#include "cellmap/sensor/replay_source.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/recording.hpp"
#include "cellmap/sim/simulator.hpp"
#include "cellmap/transport/environment_subscriber.hpp"
#include "daemon.hpp"
#include "native_modes.hpp"
#include "subscriber_arrivals.hpp"

namespace {

namespace fs = std::filesystem;
using namespace cellmap;
using Clock = std::chrono::steady_clock;  // CLOCK_MONOTONIC: comparable across processes

constexpr const char* kCell = "bench-daemon";
struct Options {
  double seconds = 40.0;         // recording length
  double rate = 30.0;            // frames per second of each camera
  double warmup = 12.0;          // seconds before the first change (the map settles meanwhile)
  double change_every = 4.0;     // seconds between the crate appearing and going
  double pass_seconds = 2.0;     // the gantry's time from one end of the table to the other
  int stops = 20;                // distinct gantry positions rendered per pass (a frame shows the nearest)
  int phase = 0;                 // frames of the gantry's back and forth gone by at the first frame
  std::vector<int> phases;       // --offline: one run per phase, scored each and together
  double no_return_range = 4.5;  // the Kinect's (time-of-flight)
  int settle_sweeps = 15;        // change.settle_sweeps (cellmapd's default)
  int sweep_frames = 0;          // the sources' sweep_frames (cellmapd's default: only sweep_period groups)
  // --set SECTION.KEY=VALUE: cellmapd config keys for the run
  std::vector<std::string> settings;
  int domain = 144;
  int anchor_frames = 6;  // frames per camera fused by the anchor
  bool offline = false;   // the recordings through the cell pipeline alone, boxes scored (run_offline)
  bool explain = false;   // --offline: the first version's boxes one by one, with the free space each blocks
};

using bench::Arrival;
using bench::kLoopbackConfig;
using bench::now_ns;

int run_subscriber(std::uint32_t domain) {
  const dds::Participant participant(domain);
  transport::EnvironmentSubscriber subscriber(
      participant, kCell,
      [](const Environment& env, const EnvironmentDelta&) { bench::report_arrival(env.version()); });
  ::pause();  // killed by the parent
  return 0;
}

// The subscriber in a process of its own; its arrivals are collected on a thread.
class SubscriberProcess {
 public:
  explicit SubscriberProcess(int domain)
      : child_({"cellmap-bench-daemon", "--subscriber", std::to_string(domain)}),
        reader_([this] { collect(); }) {}
  ~SubscriberProcess() {
    child_.stop();  // collect() sees the pipe close
    reader_.join();
  }
  // The first arrival of each version.
  [[nodiscard]] std::map<std::uint64_t, std::int64_t> arrivals() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return arrivals_;
  }

 private:
  void collect() {
    Arrival arrival{};
    while (::read(child_.in_fd(), &arrival, sizeof arrival) == sizeof arrival) {
      std::lock_guard<std::mutex> lock(mutex_);
      arrivals_.emplace(arrival.version, arrival.received_ns);
    }
  }
  mutable std::mutex mutex_;
  std::map<std::uint64_t, std::int64_t> arrivals_;
  bench::ReportingChild child_;
  std::thread reader_;  // after child_ and arrivals_: started last, by the constructor
};

// --- the recordings
// ------------------------------------------------------------------------------------------

using bench::d435_848x480;

// The crate that appears on the table, clear of every obstacle of the default cell.
sim::Obstacle crate() {
  sim::Obstacle o;
  o.name = "bench_crate";
  o.shape = sim::BoxShape{Eigen::Vector3d(0.15, 0.1, 0.1)};
  o.X_CO = Eigen::Translation3d(1.0, 1.2, 0.85) * Eigen::Isometry3d::Identity();
  return o;
}

struct Camera {
  Camera(std::string name, const PinholeIntrinsics& intrinsics, double no_return_range)
      : name(std::move(name)), intrinsics(intrinsics), no_return_range(no_return_range) {}
  std::string name;  // the scene's sensor
  PinholeIntrinsics intrinsics;
  double no_return_range;
  Eigen::Isometry3d X_ES = Eigen::Isometry3d::Identity();
  std::vector<Frame> anchor_frames;  // the first frames, posed, for the anchor
};

class Recording {
 public:
  Recording(const Options& options, fs::path dir) : options_(options), dir_(std::move(dir)) {
    pass_frames_ =
        std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(options.pass_seconds * options.rate)));
    stops_ = static_cast<int>(
        std::clamp<std::size_t>(static_cast<std::size_t>(options.stops), 2, pass_frames_ + 1));
    frames_ = static_cast<std::size_t>(std::lround(options.seconds * options.rate));
  }

  // The gantry's stop nearest to where it is at frame i: back and forth along the default plan's line over
  // the table, `phase` frames into it at frame 0.
  [[nodiscard]] int stop_of(std::size_t i) const {
    const std::size_t j = (i + static_cast<std::size_t>(options_.phase)) % (2 * pass_frames_);
    const double along =
        j < pass_frames_ ? double(j) / double(pass_frames_) : 2.0 - double(j) / double(pass_frames_);
    return static_cast<int>(std::lround(along * (stops_ - 1)));
  }
  [[nodiscard]] Eigen::VectorXd q_at(int stop) const {
    return Eigen::Vector3d(0.5 + 2.0 * stop / (stops_ - 1), 1.0, 0.0);
  }
  [[nodiscard]] double stamp_of(std::size_t i) const { return static_cast<double>(i) / options_.rate; }
  // Whether the crate stands on the table at `t`.
  [[nodiscard]] bool crate_at(double t) const {
    if (t < options_.warmup) return false;
    return static_cast<long>((t - options_.warmup) / options_.change_every) % 2 == 0;
  }
  [[nodiscard]] std::size_t changes() const { return changes_between(0.0, stamp_of(frames_ - 1)); }
  // Changes of the crate in the frames stamped in (from, to].
  [[nodiscard]] std::size_t changes_between(double from, double to) const {
    std::size_t n = 0;
    for (std::size_t i = 1; i < frames_; ++i) {
      const double t = stamp_of(i);
      if (t > from && t <= to) n += crate_at(t) != crate_at(stamp_of(i - 1));
    }
    return n;
  }
  [[nodiscard]] std::size_t frames() const { return frames_; }

  // Renders `camera`'s stops with and without the crate and writes its replay directory.
  void write(Camera& camera) const {
    const fs::path dir = dir_ / camera.name;
    fs::create_directories(dir);
    for (const bool with_crate : {false, true}) {
      if (with_crate && changes() == 0) continue;  // never shown
      sim::Scene scene = sim::default_scene();
      const int sensor = scene.find_sensor(camera.name);
      scene.sensors[static_cast<std::size_t>(sensor)].intrinsics = camera.intrinsics;
      camera.X_ES = scene.sensors[static_cast<std::size_t>(sensor)].X_ES;
      if (with_crate) scene.obstacles.push_back(crate());
      // Without the gantry: the recordings carry no robot pose for a self filter, so they show the cell as
      // the filter would leave it (the robot mapped as an obstacle would make versions of its own motion).
      const sim::Simulator simulator(std::move(scene), sim::SimOptions{true, 2, false});
      for (int stop = 0; stop < stops_; ++stop) {
        sim::SimFrame rendered =
            simulator.render(sensor, q_at(stop), 0.0, with_crate ? 1 : 0, static_cast<std::uint64_t>(stop));
        const DepthImage& depth = *rendered.frame.depth;
        write_depth_png((dir / image(with_crate, stop)).string(),
                        RawDepth{depth.intrinsics.width, depth.intrinsics.height, depth.depth});
        if (!with_crate && static_cast<int>(camera.anchor_frames.size()) < options_.anchor_frames)
          camera.anchor_frames.push_back(std::move(rendered.frame));
      }
    }
    sim::write_intrinsics(dir / "intrinsics.yaml", camera.intrinsics);
    const sim::Scene scene = sim::default_scene();
    std::vector<ReplayEntry> entries;
    for (std::size_t i = 0; i < frames_; ++i) {
      const double t = stamp_of(i);
      const int stop = stop_of(i);
      entries.push_back(ReplayEntry{image(crate_at(t), stop), t, scene.robot.tool_pose(q_at(stop))});
    }
    write_replay_poses((dir / "poses.csv").string(), entries);
  }

 private:
  static std::string image(bool with_crate, int stop) {
    return (with_crate ? "crate_" : "empty_") + std::to_string(stop) + ".png";
  }
  Options options_;
  fs::path dir_;
  std::size_t pass_frames_ = 1;
  int stops_ = 0;
  std::size_t frames_ = 0;
};

std::string yaml_vector(const Eigen::Vector3d& v) {
  char text[128];
  std::snprintf(text, sizeof text, "[%.17g, %.17g, %.17g]", v.x(), v.y(), v.z());
  return text;
}

std::string source_yaml(const Camera& camera, const fs::path& dir, int sweep_frames) {
  const Eigen::Quaterniond r(camera.X_ES.linear());
  char rotation[128];
  std::snprintf(rotation, sizeof rotation, "[%.17g, %.17g, %.17g, %.17g]", r.w(), r.x(), r.y(), r.z());
  return "  - {kind: replay, sensor: " + camera.name + ", sweep_frames: " + std::to_string(sweep_frames) +
         ", no_return_range: " + std::to_string(camera.no_return_range) +
         ", mount: tool, pose: {position: " + yaml_vector(camera.X_ES.translation()) +
         ", rotation: " + rotation + "}, replay: {directory: " + (dir / camera.name).string() +
         ", playback: recorded}}\n";
}

// --- the run ---------------------------------------------------------------------------------------------

std::int64_t ns_of(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

// What the processing thread reported, sweep by sweep.
class Traces {
 public:
  void add(const daemon::SweepTrace& trace) {
    Sweep sweep;
    sweep.stamp = trace.sweep->stamp;
    sweep.taken_ns = ns_of(trace.taken);
    sweep.published_ns = ns_of(trace.published);
    for (const SweepFrame& f : trace.sweep->frames) ++sweep.frames_by_camera[f.frame.sensor];
    sweep.report = trace.report;
    if (sweep.report) sweep.report->changes = {};
    sweep.persist = trace.persist;
    sweep.map_state = trace.map_state;
    sweep.publish = trace.publish;
    sweep.version = trace.version;
    sweep.acquisition_cpu = trace.acquisition_cpu;
    std::lock_guard<std::mutex> lock(mutex_);
    sweeps_.push_back(std::move(sweep));
  }
  struct Sweep {
    double stamp = 0.0;
    std::int64_t taken_ns = 0;      // when the processing thread took the sweep
    std::int64_t published_ns = 0;  // when its version went out
    std::map<std::string, std::size_t> frames_by_camera;
    std::optional<SweepReport> report;
    daemon::StepCost persist, publish, map_state;
    std::uint64_t version = 0;
    double acquisition_cpu = 0.0;
  };
  [[nodiscard]] std::vector<Sweep> sweeps() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return sweeps_;
  }
  [[nodiscard]] double last_stamp() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return sweeps_.empty() ? -1.0 : sweeps_.back().stamp;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Sweep> sweeps_;
};

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5)];
}

double process_cpu_seconds() {
  return static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
}

// CPU seconds per frame of OctoMap's discretized insertPointCloud (the anchor) and of OccupancyMap::integrate
// (the fusion bench's path: each frame a sweep of its own), on the cameras' first frames.
std::pair<double, double> fusion_per_frame(const std::vector<Camera>& cameras) {
  const OccupancyConfig config;
  std::vector<Sweep> sweeps;
  std::vector<octomap::Pointcloud> clouds;
  for (const Camera& camera : cameras) {
    for (const Frame& frame : camera.anchor_frames) {
      Sweep sweep;
      sweep.scans.push_back(to_scan(frame));
      octomap::Pointcloud cloud;
      for (const auto& p : sweep.scans.front().points_C.points)
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) cloud.push_back(p.x, p.y, p.z);
      clouds.push_back(std::move(cloud));
      sweeps.push_back(std::move(sweep));
    }
  }
  if (sweeps.empty()) return {NAN, NAN};
  double start = process_cpu_seconds();
  octomap::OcTree tree(config.resolution);
  apply_sensor_model(config, tree);
  for (std::size_t i = 0; i < sweeps.size(); ++i) {
    const Eigen::Vector3d& o = sweeps[i].scans.front().origin_C;
    tree.insertPointCloud(clouds[i], octomap::point3d(float(o.x()), float(o.y()), float(o.z())),
                          config.max_range, false, true);
  }
  const double anchor = (process_cpu_seconds() - start) / static_cast<double>(sweeps.size());
  start = process_cpu_seconds();
  OccupancyMap map(config);
  for (const Sweep& sweep : sweeps) map.integrate(sweep);
  const double ours = (process_cpu_seconds() - start) / static_cast<double>(sweeps.size());
  return {anchor, ours};
}

double load_average() {
  double load[1] = {NAN};
  ::getloadavg(load, 1);
  return load[0];
}

struct Totals {
  std::map<std::string, std::size_t> fused_by_camera;
  std::size_t fused = 0;
  double filter = 0, fuse = 0, change = 0, segment = 0, persist = 0, publish = 0, map_state = 0;  // CPU s
  double fuse_wall = 0;
  double gathering_wall = 0;   // seconds the gathering thread spent on frames (self filter, voxels; wall)
  double processing_wall = 0;  // seconds the processing thread spent on sweeps (every stage, wall)
  std::size_t versions = 0;    // sweeps that published a version
};

// Wall seconds the gathering thread spent on one sweep's frames as they came.
double gathering_wall(const SweepReport& r) {
  return r.t_gathering;
}

// Wall seconds the processing thread spent on one sweep once it was gathered until its version was
// published, stage by stage: what a confirming frame waits for after its sweep ended.
double closing_wall(const Traces::Sweep& s) {
  const SweepReport& r = *s.report;
  return r.t_update + r.t_change + r.t_segment + s.persist.wall + s.publish.wall;
}

Totals add_up(const std::vector<Traces::Sweep>& sweeps) {
  Totals t;
  std::uint64_t version = sweeps.empty() ? 0 : sweeps.front().version;
  for (const Traces::Sweep& s : sweeps) {
    if (!s.report) continue;
    for (const auto& [camera, n] : s.frames_by_camera) {
      t.fused_by_camera[camera] += n;
      t.fused += n;
    }
    t.filter += s.report->cpu_filter;
    t.fuse += s.report->cpu_fuse;
    t.fuse_wall += s.report->t_fuse;
    t.change += s.report->cpu_change;
    t.segment += s.report->cpu_segment;
    t.persist += s.persist.cpu;
    t.map_state += s.map_state.cpu;
    t.publish += s.publish.cpu;
    t.gathering_wall += gathering_wall(*s.report);
    t.processing_wall += closing_wall(s) + s.map_state.wall;
    if (s.version != version) ++t.versions;
    version = s.version;
  }
  return t;
}

// The sweeps that made a version, the first version (the settled map) left out: each one's last frame is
// the frame that confirmed the version's change.
std::vector<const Traces::Sweep*> confirming_sweeps(const std::vector<Traces::Sweep>& sweeps) {
  std::vector<const Traces::Sweep*> confirming;
  std::uint64_t version = 0;
  bool first = true;
  for (const Traces::Sweep& s : sweeps) {
    if (s.version == version) continue;
    version = s.version;
    if (first) {
      first = false;
      continue;
    }
    confirming.push_back(&s);
  }
  return confirming;
}

// Latency from each version's confirming frame (the last frame of the sweep that made it, at the time its
// replay delivered it) to its arrival at the subscriber, ms; the first version left out.
std::vector<double> confirm_to_delta_ms(const std::vector<Traces::Sweep>& sweeps,
                                        const std::map<std::uint64_t, std::int64_t>& arrivals,
                                        std::int64_t start_ns) {
  std::vector<double> latencies;
  for (const Traces::Sweep* s : confirming_sweeps(sweeps)) {
    const auto arrival = arrivals.find(s->version);
    if (arrival == arrivals.end()) continue;
    const double delivered_ns = static_cast<double>(start_ns) + s->stamp * 1e9;
    latencies.push_back((static_cast<double>(arrival->second) - delivered_ns) / 1e6);
  }
  return latencies;
}

// The processing of the sweeps that made a version after the first, stage by stage (wall ms, p50 and max):
// what a confirming sweep costs once it was gathered (its frames were fused as they came).
void print_close(const std::vector<Traces::Sweep>& sweeps) {
  std::vector<double> update, change, segment, persist, publish, whole, map_state;
  for (const Traces::Sweep* s : confirming_sweeps(sweeps)) {
    if (!s->report) continue;
    update.push_back(1e3 * s->report->t_update);
    change.push_back(1e3 * s->report->t_change);
    segment.push_back(1e3 * s->report->t_segment);
    persist.push_back(1e3 * s->persist.wall);
    map_state.push_back(1e3 * s->map_state.wall);
    publish.push_back(1e3 * s->publish.wall);
    whole.push_back(1e3 * closing_wall(*s));
  }
  const auto p50_max = [](const std::vector<double>& v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.0f/%.0f", percentile(v, 0.5), percentile(v, 1.0));
    return std::string(text);
  };
  std::printf(
      "close of a confirming sweep, wall ms p50/max (%zu versions after the first): map update %s, "
      "change %s, re-segmentation %s, persist %s, publish %s, whole %s; then the map state %s\n",
      whole.size(), p50_max(update).c_str(), p50_max(change).c_str(), p50_max(segment).c_str(),
      p50_max(persist).c_str(), p50_max(publish).c_str(), p50_max(whole).c_str(), p50_max(map_state).c_str());
}

void print_stage(const char* stage, double cpu, std::size_t frames, const char* note) {
  std::printf("  %-18s %9.2f ms %s\n", stage, frames ? 1e3 * cpu / static_cast<double>(frames) : NAN, note);
}

// A temporary directory, removed with everything in it.
struct ScratchDir {
  fs::path path = fs::temp_directory_path() / ("cellmap-bench-daemon-" + std::to_string(::getpid()));
  ScratchDir() { fs::create_directories(path); }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

void write_recordings(const Options& options, const Recording& recording, std::vector<Camera>& cameras) {
  const auto render_start = Clock::now();
  for (Camera& camera : cameras) recording.write(camera);
  std::printf(
      "recordings: %zu frames per camera at %.1f Hz (%.1f s), Kinect v2 512x424 (no_return_range %.1f m) "
      "and RealSense D435 848x480; the gantry %d frames into its back and forth at the first frame; the "
      "crate "
      "appears or goes %zu times from %.1f s on, every %.1f s; rendered and written in %.1f s\n",
      recording.frames(), options.rate, options.seconds, options.no_return_range, options.phase,
      recording.changes(), options.warmup, options.change_every,
      std::chrono::duration<double>(Clock::now() - render_start).count());
}

// The --set values as the config's sections: SECTION -> "KEY: VALUE, ..." (a flow map's inside).
std::map<std::string, std::string> config_sections(const std::vector<std::string>& settings) {
  std::map<std::string, std::string> sections;
  for (const std::string& setting : settings) {
    const std::size_t dot = setting.find('.'), equals = setting.find('=');
    if (dot == 0 || dot == std::string::npos || equals == std::string::npos || equals < dot + 2)
      throw Error("--set wants SECTION.KEY=VALUE, got '" + setting + "'");
    std::string& keys = sections[setting.substr(0, dot)];
    keys += (keys.empty() ? "" : ", ") + setting.substr(dot + 1, equals - dot - 1) + ": " +
            setting.substr(equals + 1);
  }
  return sections;
}

daemon::DaemonConfig daemon_config(const Options& options, const std::vector<Camera>& cameras,
                                   const fs::path& dir) {
  std::map<std::string, std::string> sections = config_sections(options.settings);
  std::string& change = sections["change"];
  change = "settle_sweeps: " + std::to_string(options.settle_sweeps) + (change.empty() ? "" : ", ") + change;
  std::string yaml = "cell: " + std::string(kCell) + "\ndomain: " + std::to_string(options.domain) +
                     "\nstate_dir: " + (dir / "state").string() + "\nlog_level: warn\n";
  for (const auto& [section, keys] : sections) yaml += section + ": {" + keys + "}\n";
  yaml += "sources:\n";
  for (const Camera& camera : cameras) yaml += source_yaml(camera, dir, options.sweep_frames);
  return daemon::DaemonConfig::parse(yaml, "bench", dir);
}

// What one run of the daemon over the recordings left.
struct DaemonRun {
  std::vector<Traces::Sweep> sweeps;
  std::int64_t start_ns = 0;
  double seconds = 0.0;
  double cpu = 0.0;  // the whole process
  double load_start = 0.0;
  bool finished = false;  // the last frames were processed before giving up
};

// Runs the daemon until the last recorded frames were processed (or long after the recording ended).
DaemonRun run_daemon(const Options& options, const Recording& recording, daemon::DaemonConfig config,
                     const daemon::Signals& signals) {
  // Both recordings play on one clock that starts once the daemon is up, so a frame's due time is known
  // here: the latency counts from when its camera would have delivered it, not from when a replay opened.
  const auto first_frame_due = Clock::now() + std::chrono::seconds(1);
  for (daemon::SourceConfig& source : config.sources)
    std::get<ReplayConfig>(source.camera.source).start = first_frame_due;
  Traces traces;
  daemon::RunOptions run_options;
  run_options.on_sweep = [&traces](const daemon::SweepTrace& trace) { traces.add(trace); };
  daemon::Daemon daemon(config, run_options);
  if (Clock::now() > first_frame_due) std::printf("the daemon took over 1 s to start: frames play late\n");

  const double last_stamp = recording.stamp_of(recording.frames() - 1);
  DaemonRun result;
  std::atomic<bool> finished{false};
  std::thread stopper([&] {
    const auto give_up = Clock::now() + std::chrono::duration<double>(options.seconds * 3 + 60);
    while (traces.last_stamp() < last_stamp && Clock::now() < give_up)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the last version's way to the subscriber
    finished = true;
    ::kill(::getpid(), SIGTERM);
  });
  const double cpu_start = process_cpu_seconds();
  result.load_start = load_average();
  result.start_ns = ns_of(first_frame_due);
  daemon.run(signals);
  result.seconds = static_cast<double>(now_ns() - result.start_ns) / 1e9;
  result.cpu = process_cpu_seconds() - cpu_start;
  stopper.join();
  result.finished = finished;
  result.sweeps = traces.sweeps();
  return result;
}

void print_frames(const Options& options, const Recording& recording, const std::vector<Camera>& cameras,
                  const DaemonRun& run, const Totals& t) {
  const std::size_t played = recording.frames() * cameras.size();
  std::printf(
      "\ncellmapd, %zu cameras at %.1f Hz for %.1f s (run %.1f s, load average %.2f at start, %.2f at end)\n",
      cameras.size(), options.rate, options.seconds, run.seconds, run.load_start, load_average());
  for (const Camera& camera : cameras) {
    const std::size_t fused = t.fused_by_camera.count(camera.name) ? t.fused_by_camera.at(camera.name) : 0;
    std::printf("  %-10s frames fused %5zu of %5zu, %6.1f per second\n", camera.name.c_str(), fused,
                recording.frames(), static_cast<double>(fused) / options.seconds);
  }
  std::printf("frames dropped: %zu of %zu\n", played - t.fused, played);
  std::vector<double> waits;  // from a sweep's last frame being due to the end of its processing
  for (const Traces::Sweep& s : run.sweeps)
    waits.push_back(static_cast<double>(s.published_ns - run.start_ns) / 1e6 - s.stamp * 1e3);
  std::printf("sweep delay, last frame due to its version out: p50 %.0f ms, max %.0f ms\n",
              percentile(waits, 0.5), percentile(waits, 1.0));
  std::printf("sweeps processed: %zu, versions published: %zu\n", run.sweeps.size(), t.versions);
  std::printf(
      "gathering thread busy %.0f %% of the run (wall time fusing frames as they came), processing thread "
      "%.0f %% (map update, change, re-segmentation, persist, publish, map state)\n",
      100.0 * t.gathering_wall / run.seconds, 100.0 * t.processing_wall / run.seconds);
}

void print_cpu(const DaemonRun& run, const Totals& t, std::size_t played) {
  const double acquisition = run.sweeps.empty() ? 0.0 : run.sweeps.back().acquisition_cpu;
  std::printf("CPU per fused frame by stage (each on its thread, with the helper threads it started):\n");
  print_stage("acquisition", acquisition, played,
              "(camera threads, per frame played: read, decode, pose, group)");
  print_stage("self filter", t.filter, t.fused,
              "(gathering thread: frames to cell-frame scans, no-return rays; replays carry no robot)");
  print_stage("fusion", t.fuse, t.fused, "(gathering thread as frames come, map update at a sweep's end)");
  print_stage("change", t.change, t.fused, "");
  print_stage("re-segmentation", t.segment, t.fused, "(sweeps with a change, and the first version)");
  print_stage("persist", t.persist, t.fused, "(processing thread: the version's boxes to disk)");
  print_stage("publish", t.publish, t.fused, "(processing thread: snapshot and delta)");
  print_stage("map state", t.map_state, t.fused, "(processing thread: the map to disk, after publishing)");
  print_stage("whole process", run.cpu, t.fused, "(every thread, DDS included)");
  const auto per_version = [&](double cpu) {
    return t.versions ? 1e3 * cpu / static_cast<double>(t.versions) : NAN;
  };
  std::printf("  per version: persist %.1f ms CPU, publish %.2f ms CPU, map state %.1f ms CPU\n",
              per_version(t.persist), per_version(t.publish), per_version(t.map_state));
}

void print_latency(const DaemonRun& run, const SubscriberProcess& subscriber) {
  const std::map<std::uint64_t, std::int64_t> arrivals = subscriber.arrivals();
  std::printf("versions received by the subscriber: %zu (the last: %llu)\n", arrivals.size(),
              arrivals.empty() ? 0ULL : static_cast<unsigned long long>(arrivals.rbegin()->first));
  const std::vector<double> latencies = confirm_to_delta_ms(run.sweeps, arrivals, run.start_ns);
  std::printf(
      "confirm-to-delta latency: %zu versions after the first, p50 %.1f ms, p99 %.1f ms, max %.1f ms\n",
      latencies.size(), percentile(latencies, 0.5), percentile(latencies, 0.99), percentile(latencies, 1.0));
}

// The slowest versions' latency split where it went: from the confirming frame being due until the
// processing thread took its sweep (the last frames' fusion, or a sweep still being processed), the close
// stage by stage, and from the publishing call's return to the subscriber's arrival (delivery, sharing the
// cores with the map state and the next frames; negative when the subscriber ran before the publisher
// got the core back).
void print_slowest(const DaemonRun& run, const SubscriberProcess& subscriber, std::size_t count) {
  const std::map<std::uint64_t, std::int64_t> arrivals = subscriber.arrivals();
  struct Split {
    double latency, gathered, close, delivery;
    const Traces::Sweep* sweep;
  };
  std::vector<Split> splits;
  for (const Traces::Sweep* s : confirming_sweeps(run.sweeps)) {
    const auto arrival = arrivals.find(s->version);
    if (arrival == arrivals.end() || !s->report) continue;
    const double due_ms = static_cast<double>(run.start_ns) / 1e6 + s->stamp * 1e3;
    const double taken_ms = static_cast<double>(s->taken_ns) / 1e6;
    const double published_ms = static_cast<double>(s->published_ns) / 1e6;
    const double arrival_ms = static_cast<double>(arrival->second) / 1e6;
    splits.push_back(
        {arrival_ms - due_ms, taken_ms - due_ms, published_ms - taken_ms, arrival_ms - published_ms, s});
  }
  std::sort(splits.begin(), splits.end(),
            [](const Split& a, const Split& b) { return a.latency > b.latency; });
  if (splits.size() > count) splits.resize(count);
  std::printf(
      "slowest versions, ms: latency = due to taken + close (update, change, re-segmentation, "
      "persist, publish) + delivery; voxels re-segmented, re-segmentation CPU\n");
  for (const Split& x : splits) {
    const SweepReport& r = *x.sweep->report;
    std::printf("  version %llu: %.1f = %.1f + %.1f (%.1f, %.1f, %.1f, %.1f, %.1f) + %.1f; %zu, %.1f\n",
                static_cast<unsigned long long>(x.sweep->version), x.latency, x.gathered, x.close,
                1e3 * r.t_update, 1e3 * r.t_change, 1e3 * r.t_segment, 1e3 * x.sweep->persist.wall,
                1e3 * x.sweep->publish.wall, x.delivery, r.evidence, 1e3 * r.cpu_segment);
  }
}

void print_ratios(const std::vector<Camera>& cameras, const Totals& t, std::size_t played) {
  const auto [anchor, bench_fusion] = fusion_per_frame(cameras);
  const double daemon_fusion = t.fused ? t.fuse / static_cast<double>(t.fused) : NAN;
  std::printf(
      "fusion CPU per frame: daemon %.1f ms, the same frames fused one per sweep %.1f ms, OctoMap "
      "insertPointCloud(discretize=true) %.1f ms\n",
      1e3 * daemon_fusion, 1e3 * bench_fusion, 1e3 * anchor);
  std::printf("ratio daemon fusion per frame (vs discretized insert): %.2fx\n", anchor / daemon_fusion);
  std::printf("ratio frames fused (vs frames played): %.3fx\n",
              played ? static_cast<double>(t.fused) / static_cast<double>(played) : NAN);
}

// --- offline: the recordings through the cell pipeline alone, the boxes scored ---------------------------

// How the boxes stand for the cell as it is: their count, the free space they block over the obstacles' own
// volume (the whole cell, research/evaluate.hpp), and the crate: boxed on its own while it stands there (a
// box with IoU >= 0.2 with it, holding its centre), its place free while it is away.
struct Standing {
  std::size_t boxes = 0;
  double blocked = 0.0;
  bool crate_there = false, crate_boxed = false, place_free = false;
};

Standing standing(const std::vector<Box>& boxes, bool crate_there) {
  sim::Scene scene = sim::default_scene();
  if (crate_there) scene.obstacles.push_back(crate());
  const sim::BoxScore score = sim::score_boxes(scene.obstacles, boxes, Cloud(), scene.cell, 0.02);
  const Eigen::Vector3d centre = crate().X_CO.translation();
  const bool held = std::any_of(boxes.begin(), boxes.end(), [&](const Box& b) { return b.contains(centre); });
  Standing out;
  out.boxes = boxes.size();
  out.blocked = score.blocked_free_space;
  out.crate_there = crate_there;
  for (const sim::ObjectScore& o : score.objects) out.crate_boxed |= o.name == "bench_crate" && o.iou >= 0.2;
  out.crate_boxed = out.crate_boxed && held;
  out.place_free = !held;
  return out;
}

// "box ID at (x, y, z), X x Y x Z m, N voxels": where a box is, its size along its own axes, what it holds.
std::string box_text(const Box& b) {
  char text[160];
  std::snprintf(text, sizeof text, "box %llu at (%.2f, %.2f, %.2f), %.2f x %.2f x %.2f m, %llu voxels",
                static_cast<unsigned long long>(b.id), b.center.x(), b.center.y(), b.center.z(),
                2 * b.half_extents.x(), 2 * b.half_extents.y(), 2 * b.half_extents.z(),
                static_cast<unsigned long long>(b.points));
  return text;
}

// Each box of the cell without the crate: centre, size, voxels, the free space it blocks alone (m³ and
// over the obstacles' volume) and the objects it matches best, largest blocked first: where the blocked free
// space of a version is.
void explain(const std::vector<Box>& boxes) {
  const sim::Scene scene = sim::default_scene();
  const sim::BoxScore all = sim::score_boxes(scene.obstacles, boxes, Cloud(), scene.cell, 0.02);
  std::vector<std::pair<double, const Box*>> blocked;
  for (const Box& b : boxes) {
    const sim::BoxScore alone = sim::score_boxes(scene.obstacles, {b}, Cloud(), scene.cell, 0.02);
    blocked.emplace_back(alone.blocked_free_space * alone.true_volume, &b);
  }
  std::sort(blocked.begin(), blocked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [m3, b] : blocked) {
    std::string objects;
    for (const sim::ObjectScore& o : all.objects) {
      if (o.box != b->id) continue;
      char iou[32];
      std::snprintf(iou, sizeof iou, " (IoU %.2f)", o.iou);
      objects += " " + o.name + iou;
    }
    std::printf("    %s: blocks %.4f m3 (%.1f %%);%s\n", box_text(*b).c_str(), m3, 100 * m3 / all.true_volume,
                objects.empty() ? " no object's best box" : objects.c_str());
  }
}

void print_added(const Reconciled& change) {
  for (const Box& b : change.added) std::printf("    added %s\n", box_text(b).c_str());
  for (const Box& b : change.modified) std::printf("    modified %s\n", box_text(b).c_str());
}

// The cameras' replays as cellmapd opens them (their directories, poses and intrinsics).
std::vector<std::unique_ptr<ReplaySource>> open_replays(const std::vector<Camera>& cameras,
                                                        const fs::path& dir) {
  std::vector<std::unique_ptr<ReplaySource>> replays;
  for (const Camera& camera : cameras) {
    ReplayConfig config;
    config.name = camera.name;
    config.directory = (dir / camera.name).string();
    replays.push_back(std::make_unique<ReplaySource>(config));
    const SourceStatus status = replays.back()->open();
    if (!status.reason.empty()) throw Error("replay " + camera.name + ": " + status.reason);
  }
  return replays;
}

void print_standing(double stamp, const Standing& s) {
  std::printf(
      "  at %5.2f s, the crate %s: %zu boxes blocking %.1f %% of the obstacles' volume in free space; %s\n",
      stamp, s.crate_there ? "there" : "away", s.boxes, 100 * s.blocked,
      s.crate_there ? (s.crate_boxed ? "the crate boxed on its own" : "the crate NOT boxed on its own")
                    : (s.place_free ? "its place free" : "its place blocked"));
}

// The two native cameras the recordings are made for: the Kinect v2 (clearing on no return) and the D435.
std::vector<Camera> native_cameras(const Options& options) {
  return {{"kinect", sim::default_intrinsics(sim::SensorModel::kKinectV2), options.no_return_range},
          {"realsense", d435_848x480(), 0.0}};
}

// The versions after the first, by the box ids each added, modified or removed, so that versions made only
// of boxes that came and went (added and removed within kTransientSeconds with no change of the crate in
// between: smear, or part of a change boxed on its own and taken back) can be counted.
class VersionLog {
 public:
  static constexpr double kTransientSeconds = 5.0;

  void add(double stamp, const Reconciled& change) {
    std::vector<std::uint64_t> ids;
    for (const Box& b : change.added) {
      added_[b.id] = stamp;
      ids.push_back(b.id);
    }
    for (const Box& b : change.modified) ids.push_back(b.id);
    for (const std::uint64_t id : change.removed) {
      removed_[id] = stamp;
      ids.push_back(id);
    }
    versions_.push_back(std::move(ids));
  }
  [[nodiscard]] std::size_t versions() const { return versions_.size(); }
  [[nodiscard]] std::size_t transient_only(const Recording& recording) const {
    return static_cast<std::size_t>(std::count_if(versions_.begin(), versions_.end(), [&](const auto& ids) {
      return std::all_of(ids.begin(), ids.end(), [&](std::uint64_t id) { return transient(id, recording); });
    }));
  }

 private:
  [[nodiscard]] bool transient(std::uint64_t id, const Recording& recording) const {
    const auto added = added_.find(id), removed = removed_.find(id);
    if (added == added_.end() || removed == removed_.end()) return false;
    return removed->second - added->second <= kTransientSeconds &&
           recording.changes_between(added->second, removed->second) == 0;
  }
  std::vector<std::vector<std::uint64_t>> versions_;  // per version: the ids it added, modified or removed
  std::map<std::uint64_t, double> added_, removed_;
};

// One phase's offline run against the criteria: versions per change of the crate after the first version,
// versions made only of boxes that came and went, how the first version stands, and the crate just before
// each of its changes (and at the end).
struct OfflineScore {
  int phase = 0;
  std::size_t changes = 0, versions = 0, transient_versions = 0;
  std::optional<Standing> first;
  std::size_t there = 0, boxed = 0, away = 0, freed = 0;
};

// Plays the recordings through CellPipeline on this thread, frame by frame in stamp order, grouped into
// sweeps by cellmapd's FrameGrouper: the daemon's versions without its threads, DDS or timing, so a run is
// the same every time. Prints each version and how the boxes stand before each change of the crate and at
// the end.
OfflineScore play_offline(const Options& options) {
  const ScratchDir dir;
  const Recording recording(options, dir.path);
  std::vector<Camera> cameras = native_cameras(options);
  write_recordings(options, recording, cameras);
  const daemon::DaemonConfig config = daemon_config(options, cameras, dir.path);
  const std::vector<std::unique_ptr<ReplaySource>> replays = open_replays(cameras, dir.path);
  CellPipeline pipeline(config.pipeline);
  FrameGrouper grouper(config.sources.front().grouping);
  FrameSweep open;
  OfflineScore score;
  score.phase = options.phase;
  score.changes = recording.changes();
  VersionLog log;
  std::size_t version = 0;
  const auto close = [&] {
    if (open.frames.empty()) return;
    const double stamp = open.stamp;
    const SweepReport report = pipeline.process(std::move(open));
    open = {};
    if (!report.change) return;
    std::printf("version %zu at %5.2f s: +%zu ~%zu -%zu, %zu boxes; %zu voxels re-segmented in %.1f ms\n",
                ++version, stamp, report.change->added.size(), report.change->modified.size(),
                report.change->removed.size(), report.boxes, report.evidence, 1e3 * report.t_segment);
    if (version > 1) {
      if (options.explain) print_added(*report.change);
      return log.add(stamp, *report.change);
    }
    score.first = standing(pipeline.boxes(), false);
    print_standing(stamp, *score.first);
    if (options.explain) explain(pipeline.boxes());
  };
  for (std::size_t i = 0; i < recording.frames(); ++i) {
    for (std::size_t c = 0; c < cameras.size(); ++c) {
      Frame frame = replays[c]->load(i);
      frame.X_CS = replays[c]->poses()[i].X_CE * cameras[c].X_ES;
      const FramePlace place = grouper.place(frame.sensor, frame.stamp);
      if (place.ends_open_sweep) close();
      open.stamp = frame.stamp;
      open.frames.push_back(SweepFrame{std::move(frame), std::nullopt, cameras[c].no_return_range});
      if (place.completes_sweep) close();
    }
    const double t = recording.stamp_of(i);
    const bool last = i + 1 == recording.frames();
    if (t < options.warmup ||
        (!last && recording.crate_at(recording.stamp_of(i + 1)) == recording.crate_at(t)))
      continue;
    const Standing now = standing(pipeline.boxes(), recording.crate_at(t));
    print_standing(t, now);
    (now.crate_there ? score.there : score.away) += 1;
    score.boxed += now.crate_there && now.crate_boxed;
    score.freed += !now.crate_there && now.place_free;
  }
  close();
  score.versions = log.versions();
  score.transient_versions = log.transient_only(recording);
  return score;
}

double per_change(std::size_t versions, std::size_t changes) {
  return changes ? static_cast<double>(versions) / static_cast<double>(changes) : NAN;
}

void print_score(const OfflineScore& s) {
  char first[96] = "never made";
  if (s.first)
    std::snprintf(first, sizeof first, "%zu boxes blocking %.1f %%", s.first->boxes, 100 * s.first->blocked);
  std::printf(
      "phase %d: %zu versions after the first for %zu changes of the crate (%.2f a change), %zu of them only "
      "boxes that came and went within %.0f s; the first version %s; the crate boxed on its own %zu of %zu "
      "times, its place free %zu of %zu times (just before each change, and at the end)\n",
      s.phase, s.versions, s.changes, per_change(s.versions, s.changes), s.transient_versions,
      VersionLog::kTransientSeconds, first, s.boxed, s.there, s.freed, s.away);
}

// The criteria over every phase: versions per change, versions only of boxes that came and went, the first
// version's blocked free space (mean and worst), the crate boxed at every presence and its place free at
// every absence.
void print_overall(const std::vector<OfflineScore>& scores) {
  std::size_t changes = 0, versions = 0, transient = 0, there = 0, boxed = 0, away = 0, freed = 0, firsts = 0;
  double blocked_sum = 0.0, blocked_worst = 0.0;
  for (const OfflineScore& s : scores) {
    changes += s.changes;
    versions += s.versions;
    transient += s.transient_versions;
    there += s.there, boxed += s.boxed, away += s.away, freed += s.freed;
    if (!s.first) continue;
    ++firsts;
    blocked_sum += s.first->blocked;
    blocked_worst = std::max(blocked_worst, s.first->blocked);
  }
  std::printf(
      "over %zu phases: %.2f versions a change of the crate (goal <= 1.1), %zu versions only of boxes that "
      "came and went (goal 0), the first version blocking %.1f %% of the obstacles' volume in free space on "
      "average and %.1f %% at worst (goal <= 25 %%, first versions made: %zu), the crate boxed on its "
      "own %zu of %zu times and its place free %zu of %zu times (goal: every time)\n",
      scores.size(), per_change(versions, changes), transient,
      firsts ? 100 * blocked_sum / static_cast<double>(firsts) : NAN, 100 * blocked_worst, firsts, boxed,
      there, freed, away);
}

// One offline run per phase (--phases, else --phase), each scored, then all of them together.
int run_offline(const Options& options) {
  std::vector<OfflineScore> scores;
  for (const int phase : options.phases.empty() ? std::vector<int>{options.phase} : options.phases) {
    Options at = options;
    at.phase = phase;
    scores.push_back(play_offline(at));
    print_score(scores.back());
  }
  for (const OfflineScore& s : scores) print_score(s);
  print_overall(scores);
  return 0;
}

int run(const Options& options) {
  const ScratchDir dir;
  const Recording recording(options, dir.path);
  std::vector<Camera> cameras = native_cameras(options);
  write_recordings(options, recording, cameras);

  // Before any thread (the subscriber's reader, the daemon's): they all inherit the blocked signals.
  const daemon::Signals signals;
  SubscriberProcess subscriber(options.domain);
  const daemon::DaemonConfig config = daemon_config(options, cameras, dir.path);
  spdlog::set_level(spdlog::level::warn);
  const DaemonRun daemon_run = run_daemon(options, recording, config, signals);

  const Totals t = add_up(daemon_run.sweeps);
  const std::size_t played = recording.frames() * cameras.size();
  print_frames(options, recording, cameras, daemon_run, t);
  print_close(daemon_run.sweeps);
  print_cpu(daemon_run, t, played);
  print_latency(daemon_run, subscriber);
  print_slowest(daemon_run, subscriber, 3);
  print_ratios(cameras, t, played);
  return daemon_run.finished ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  ::setenv("CYCLONEDDS_URI", kLoopbackConfig, 0);  // keep the caller's configuration if there is one
  if (argc == 3 && std::strcmp(argv[1], "--subscriber") == 0)
    return run_subscriber(static_cast<std::uint32_t>(std::stoul(argv[2])));
  CLI::App app{
      "cellmap bench daemon: cellmapd fed with two native cameras of the default cell (recordings played at "
      "their recorded speed); frames fused and dropped, CPU per frame by stage, confirm-to-delta latency"};
  Options options;
  app.add_option("--seconds", options.seconds, "recording length")->check(CLI::Range(1.0, 3600.0));
  app.add_option("--rate", options.rate, "frames per second of each camera")->check(CLI::Range(0.5, 120.0));
  app.add_option("--warmup", options.warmup, "seconds before the first change")
      ->check(CLI::Range(0.0, 3600.0));
  app.add_option("--change-every", options.change_every, "seconds between changes")
      ->check(CLI::Range(0.5, 3600.0));
  app.add_option("--no-return-range", options.no_return_range, "the Kinect's no_return_range, metres")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--settle-sweeps", options.settle_sweeps,
                 "sweeps before the first version (change.settle_sweeps)")
      ->check(CLI::Range(0, 100000));
  app.add_option("--sweep-frames", options.sweep_frames,
                 "frames that close a sweep (sweep_frames; 0 = only sweep_period)")
      ->check(CLI::Range(0, 100000));
  app.add_option("--stops", options.stops, "gantry positions rendered per pass")->check(CLI::Range(2, 1000));
  app.add_option(
         "--phase", options.phase,
         "frames of the gantry's back and forth gone by at the first frame: where the sweeps (grouped "
         "from the first frame's stamp) fall in its passes")
      ->check(CLI::Range(0, 100000));
  app.add_option("--phases", options.phases,
                 "--offline: one run per phase (comma-separated), each scored, then all together")
      ->delimiter(',')
      ->check(CLI::Range(0, 100000));
  app.add_flag("--explain", options.explain,
               "--offline: print the first version's boxes, each with the free space it blocks, and the "
               "boxes each later version adds or modifies");
  app.add_option("--set", options.settings,
                 "a cellmapd config key for the run, SECTION.KEY=VALUE (e.g. change.gather_sweeps=2); "
                 "repeatable")
      ->type_name("SECTION.KEY=VALUE");
  app.add_option("--domain", options.domain, "DDS domain id")->check(CLI::Range(0, 232));
  app.add_flag("--offline", options.offline,
               "play the recordings through the cell pipeline alone, as fast as it goes, and score the boxes "
               "before each change of the crate (no daemon, no DDS, no timing: the same every run)");
  CLI11_PARSE(app, argc, argv);
  if ((!options.phases.empty() || options.explain) && !options.offline) {
    std::fprintf(stderr, "bench daemon: --phases and --explain need --offline\n");
    return 2;
  }
  try {
    return options.offline ? run_offline(options) : run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench daemon: %s\n", e.what());
    return 1;
  }
}
