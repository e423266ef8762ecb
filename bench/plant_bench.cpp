// SPDX-License-Identifier: Apache-2.0
// cellmap bench plant: many cells on one DDS domain, every part a real process on loopback.
//
// Starts N cellmapd daemons on simulated cells (cell-1 .. cell-N, each its own state directory, the OS32C
// line scanner of the default cell, exact depths), waits until a monitor in this process (EnvironmentMonitor,
// every cell) has every cell's first version, then starts N planner processes at once, each following one
// cell with the planner client (EnvironmentSubscriber). Then it injects boxes into cell-1 (added, then
// removed again: one change each) and reports
//   - discovery: the time from a planner's start until it holds its cell's snapshot (p50, max),
//   - delta latency to cell-1's planner, from the version's stamp (the daemon made it) and from the inject,
//   - what reaches the planners of the other cells: the samples of foreign cells their client library
//     received and ignored (TrackerStats::other_cells), per delta of another cell and at joining, with their
//     payload bytes (the serialized size of those samples, wire_size),
//   - RSS per daemon and per planner, UDP datagrams dropped for full receive buffers, and the load average.
// cell-1 sweeps every --change-sweep-period seconds so that a change is seen soon; the other cells sweep
// every --sweep-period (long: they only keep the machine busy as a plant would).
// Run it in a network namespace of its own (its domain's ports are fixed): scripts/plant N.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cellmap/common/error.hpp"
#include "cellmap/transport/environment_monitor.hpp"
#include "cellmap/transport/environment_subscriber.hpp"
#include "cellmap/transport/scene_edits.hpp"
#include "subscriber_arrivals.hpp"
#include "wire_size.hpp"

namespace {

namespace fs = std::filesystem;
using namespace cellmap;
using bench::now_ns;

struct Options {
  int cells = 4;
  int changes = 8;                   // boxes added to or removed from cell-1
  double sweep_period = 4.0;         // every cell but cell-1
  double change_sweep_period = 0.2;  // cell-1
  int domain = 218;
  std::string sensor = "os32c";
  double timeout = 120.0;  // seconds to wait for any one event
};

// What a planner process reports to the plant: a version it holds, or the count of foreign samples so far.
struct PlannerReport {
  enum Kind : std::int32_t { kVersion, kOtherCells } kind;
  std::uint64_t value;       // version, or TrackerStats::other_cells
  std::int64_t stamp_ns;     // the version's stamp (CLOCK_REALTIME)
  std::int64_t received_ns;  // steady clock
  std::int64_t received_realtime_ns;
};

std::int64_t realtime_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void report(const PlannerReport& r) {
  if (::write(STDOUT_FILENO, &r, sizeof r) != sizeof r) std::_Exit(3);  // the plant is gone
}

// The planner process: follows `cell`, reports each version and the foreign samples its library ignored.
int run_planner(std::uint32_t domain, const std::string& cell) {
  const dds::Participant participant(domain);
  const transport::EnvironmentSubscriber subscriber(
      participant, cell, [](const Environment& environment, const EnvironmentDelta&) {
        report({PlannerReport::kVersion, environment.version(), environment.stamp_ns(), now_ns(),
                realtime_ns()});
      });
  std::uint64_t other_cells = 0;
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::uint64_t now = subscriber.stats().other_cells;
    if (now != other_cells) report({PlannerReport::kOtherCells, now, 0, now_ns(), realtime_ns()});
    other_cells = now;
  }
}

std::string cell_name(int index) {
  return "cell-" + std::to_string(index + 1);
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5)];
}

double rss_mib(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return NAN;
}

// UDP datagrams this network namespace dropped because a socket's receive buffer was full (/proc/net/snmp).
std::uint64_t udp_receive_drops() {
  std::ifstream in("/proc/net/snmp");
  std::string names, values;
  while (std::getline(in, names) && std::getline(in, values)) {
    if (names.rfind("Udp:", 0) != 0) continue;
    std::istringstream name_fields(names), value_fields(values);
    std::string name, value;
    while (name_fields >> name && value_fields >> value)
      if (name == "RcvbufErrors") return std::stoull(value);
  }
  return 0;
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

// A cellmapd process with its config and state directory under `dir`, its log in dir/cellmapd.log.
class Daemon {
 public:
  Daemon(const fs::path& program, const fs::path& dir, const std::string& cell, double sweep_period,
         const Options& options) {
    fs::create_directories(dir);
    std::ofstream(dir / "cellmapd.yaml") << "cell: " << cell << "\nsweep_period: " << sweep_period
                                         << "\nsource: {kind: sim, sensor: " << options.sensor
                                         << ", noise: false}\nchange: {settle_sweeps: 2}\n";
    const std::vector<std::string> arguments{program.string(),
                                             "--config",
                                             (dir / "cellmapd.yaml").string(),
                                             "--domain",
                                             std::to_string(options.domain),
                                             "--state-dir",
                                             (dir / "state").string()};
    const std::string log = (dir / "cellmapd.log").string();
    pid_ = ::fork();
    if (pid_ == 0) {
      std::freopen(log.c_str(), "w", stdout);
      ::dup2(STDOUT_FILENO, STDERR_FILENO);
      std::vector<char*> argv;
      for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      std::_Exit(127);
    }
  }
  ~Daemon() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    for (int i = 0; i < 100; ++i) {
      if (::waitpid(pid_, nullptr, WNOHANG) == pid_) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;
  [[nodiscard]] pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
};

// The planner processes' reports, gathered by one reading thread per planner.
class Planners {
 public:
  Planners(const Options& options, const std::string& self) : reports_(options.cells) {
    for (int i = 0; i < options.cells; ++i) {
      started_ns_.push_back(now_ns());
      children_.push_back(std::make_unique<bench::ReportingChild>(std::vector<std::string>{
          self, "--planner", cell_name(i), "--domain", std::to_string(options.domain)}));
    }
    // The readers start once children_ is whole: a reader reading its element while the vector grows would
    // read freed memory.
    for (int i = 0; i < options.cells; ++i) readers_.emplace_back([this, i] { read(i); });
  }
  ~Planners() {
    for (auto& child : children_) child->stop();  // the readers then see end of file
    for (std::thread& t : readers_) t.join();
  }
  Planners(const Planners&) = delete;
  Planners& operator=(const Planners&) = delete;

  // Waits until `done(reports of planner i)` holds; false on timeout.
  template <class Predicate>
  bool wait(int i, double timeout_s, Predicate done) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                             [&] { return done(reports_[i]); });
  }
  std::vector<PlannerReport> reports(int i) {
    const std::lock_guard<std::mutex> lock(mutex_);
    return reports_[i];
  }
  [[nodiscard]] std::int64_t started_ns(int i) const { return started_ns_[i]; }
  [[nodiscard]] pid_t pid(int i) const { return children_[i]->pid(); }

 private:
  void read(int i) {
    PlannerReport r{};
    while (::read(children_[i]->in_fd(), &r, sizeof r) == sizeof r) {
      const std::lock_guard<std::mutex> lock(mutex_);
      reports_[i].push_back(r);
      changed_.notify_all();
    }
  }

  std::vector<std::int64_t> started_ns_;
  std::vector<std::unique_ptr<bench::ReportingChild>> children_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::vector<PlannerReport>> reports_;  // guarded by mutex_
  std::vector<std::thread> readers_;
};

std::uint64_t latest(const std::vector<PlannerReport>& reports, PlannerReport::Kind kind) {
  std::uint64_t value = 0;
  for (const PlannerReport& r : reports)
    if (r.kind == kind) value = std::max(value, r.value);
  return value;
}

// What the monitor (this process) has seen: each cell's newest version and every sample's payload size.
struct MonitorView {
  std::map<std::string, std::uint64_t> version;
  std::vector<std::size_t> snapshot_bytes, delta_bytes;  // in arrival order
  std::vector<std::string> delta_cells;                  // the cell of each of delta_bytes

  void take(transport::EnvironmentMonitor& monitor, double timeout_s) {
    const auto timeout =
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(timeout_s));
    for (const transport::EnvironmentMessage& message : monitor.take(timeout)) {
      if (const auto* env = std::get_if<Environment>(&message)) {
        version[env->cell()] = std::max(version[env->cell()], env->version());
        snapshot_bytes.push_back(transport::wire_size(*env));
      } else {
        const auto& delta = std::get<EnvironmentDelta>(message);
        version[delta.cell] = std::max(version[delta.cell], delta.to_version);
        delta_bytes.push_back(transport::wire_size(delta));
        delta_cells.push_back(delta.cell);
      }
    }
  }
};

void wait_for_every_cell(transport::EnvironmentMonitor& monitor, MonitorView& view, const Options& options) {
  const std::int64_t deadline = now_ns() + static_cast<std::int64_t>(options.timeout * 1e9);
  for (;;) {
    view.take(monitor, 0.2);
    int ready = 0;
    for (int i = 0; i < options.cells; ++i) ready += view.version[cell_name(i)] > 0 ? 1 : 0;
    if (ready == options.cells) return;
    if (now_ns() > deadline)
      throw Error("only " + std::to_string(ready) + " of " + std::to_string(options.cells) +
                  " cells published a first version within " + std::to_string(options.timeout) + " s");
  }
}

struct Latencies {
  std::vector<double> from_stamp_ms, from_inject_ms;
};

// Adds (even k) or removes (odd k) a box in cell-1 and waits for cell-1's planner to hold the next version.
Latencies inject_changes(const Options& options, Planners& planners, transport::EnvironmentMonitor& monitor,
                         MonitorView& view, const transport::SceneEditWriter& writer) {
  Latencies latencies;
  for (int k = 0; k < options.changes; ++k) {
    const std::uint64_t before = latest(planners.reports(0), PlannerReport::kVersion);
    transport::SceneEdit edit =
        k % 2 == 0 ? transport::SceneEdit::add_box("plant-box", {2.12, 0.45, 0.9}, {0.1, 0.1, 0.15})
                   : transport::SceneEdit::remove("plant-box");
    edit.cell = cell_name(0);
    const std::int64_t injected_ns = now_ns();
    writer.write(edit);
    if (!planners.wait(0, options.timeout, [&](const std::vector<PlannerReport>& reports) {
          return latest(reports, PlannerReport::kVersion) > before;
        }))
      throw Error("change " + std::to_string(k) + ": no new version at cell-1's planner");
    for (const PlannerReport& r : planners.reports(0)) {
      if (r.kind != PlannerReport::kVersion || r.value <= before) continue;
      latencies.from_stamp_ms.push_back(static_cast<double>(r.received_realtime_ns - r.stamp_ns) / 1e6);
      latencies.from_inject_ms.push_back(static_cast<double>(r.received_ns - injected_ns) / 1e6);
      break;
    }
    view.take(monitor, 0.3);  // keeps the monitor's history drained; also spaces the changes
  }
  return latencies;
}

// The mean of sizes[from, end).
double mean_bytes(const std::vector<std::size_t>& sizes, std::size_t from = 0) {
  if (from >= sizes.size()) return NAN;
  double sum = 0.0;
  for (std::size_t i = from; i < sizes.size(); ++i) sum += static_cast<double>(sizes[i]);
  return sum / static_cast<double>(sizes.size() - from);
}

void print_rss(const char* what, const std::vector<double>& rss) {
  std::printf("RSS per %s: median %.1f MiB, min %.1f, max %.1f (%zu processes)\n", what, percentile(rss, 0.5),
              percentile(rss, 0.0), percentile(rss, 1.0), rss.size());
}

// A temporary directory, removed with everything in it when this goes (after the daemons that use it).
class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    char name[] = "/tmp/cellmap-plant-XXXXXX";
    if (::mkdtemp(name) == nullptr) throw Error("cannot create a temporary directory");
    path_ = name;
  }
  ~TemporaryDirectory() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::vector<std::unique_ptr<Daemon>> start_daemons(const Options& options, const fs::path& program,
                                                   const fs::path& dir) {
  std::vector<std::unique_ptr<Daemon>> daemons;
  for (int i = 0; i < options.cells; ++i) {
    daemons.push_back(std::make_unique<Daemon>(program, dir / cell_name(i), cell_name(i),
                                               i == 0 ? options.change_sweep_period : options.sweep_period,
                                               options));
  }
  return daemons;
}

// Waits for every planner's first version and prints the times from its start; returns the foreign samples
// each had received by then.
std::vector<std::uint64_t> measure_discovery(const Options& options, Planners& planners) {
  std::vector<double> discovery_ms;
  for (int i = 0; i < options.cells; ++i) {
    if (!planners.wait(i, options.timeout, [](const std::vector<PlannerReport>& reports) {
          return latest(reports, PlannerReport::kVersion) > 0;
        }))
      throw Error(cell_name(i) + "'s planner got no snapshot");
    const auto reports = planners.reports(i);
    const auto first = std::find_if(reports.begin(), reports.end(),
                                    [](const PlannerReport& r) { return r.kind == PlannerReport::kVersion; });
    discovery_ms.push_back(static_cast<double>(first->received_ns - planners.started_ns(i)) / 1e6);
  }
  std::printf(
      "discovery, planner start to its cell's snapshot: p50 %.0f ms, max %.0f ms; all %d planners "
      "within %.0f ms of the first start\n",
      percentile(discovery_ms, 0.5), percentile(discovery_ms, 1.0), options.cells,
      static_cast<double>(now_ns() - planners.started_ns(0)) / 1e6);
  std::this_thread::sleep_for(std::chrono::seconds(1));  // lets the planners report their last counts
  std::vector<std::uint64_t> joined(options.cells);
  for (int i = 0; i < options.cells; ++i) joined[i] = latest(planners.reports(i), PlannerReport::kOtherCells);
  return joined;
}

void print_latencies(const Latencies& latencies) {
  std::printf(
      "delta latency at cell-1's planner (%zu changes): version stamp to planner p50 %.1f ms, p99 %.1f "
      "ms; inject to planner (sweeps included) p50 %.0f ms, p99 %.0f ms\n",
      latencies.from_stamp_ms.size(), percentile(latencies.from_stamp_ms, 0.5),
      percentile(latencies.from_stamp_ms, 0.99), percentile(latencies.from_inject_ms, 0.5),
      percentile(latencies.from_inject_ms, 0.99));
}

// What reached the planners of cells 2..N: foreign samples per delta of another cell since `deltas_before`
// (other cells may make a version meanwhile too), and at joining.
void print_foreign(const Options& options, Planners& planners, const MonitorView& view,
                   const std::vector<std::uint64_t>& joined, std::size_t deltas_before) {
  std::vector<double> per_delta, at_join;
  for (int i = 1; i < options.cells; ++i) {
    const std::uint64_t total = latest(planners.reports(i), PlannerReport::kOtherCells);
    const auto foreign_deltas =
        std::count_if(view.delta_cells.begin() + static_cast<std::ptrdiff_t>(deltas_before),
                      view.delta_cells.end(), [&](const std::string& cell) { return cell != cell_name(i); });
    per_delta.push_back(
        foreign_deltas ? static_cast<double>(total - joined[i]) / static_cast<double>(foreign_deltas) : NAN);
    at_join.push_back(static_cast<double>(joined[i]));
  }
  std::printf(
      "at a planner of another cell: %.2f foreign samples per foreign delta (max %.2f; %zu deltas on the domain, "
      "%.0f B payload each), %.0f foreign samples at joining (snapshots %.0f B, deltas %.0f B "
      "payload on average)\n",
      percentile(per_delta, 0.5), percentile(per_delta, 1.0), view.delta_bytes.size() - deltas_before,
      mean_bytes(view.delta_bytes, deltas_before), percentile(at_join, 0.5), mean_bytes(view.snapshot_bytes),
      mean_bytes(view.delta_bytes));
}

void print_memory(const std::vector<std::unique_ptr<Daemon>>& daemons, const Planners& planners, int cells) {
  std::vector<double> daemon_rss, planner_rss;
  for (const auto& d : daemons) daemon_rss.push_back(rss_mib(d->pid()));
  for (int i = 0; i < cells; ++i) planner_rss.push_back(rss_mib(planners.pid(i)));
  print_rss("daemon", daemon_rss);
  print_rss("planner", planner_rss);
}

int run(const Options& options, const std::string& self) {
  const fs::path program = fs::path(self).parent_path() / "cellmapd";
  if (!fs::exists(program)) throw Error(program.string() + " is not built");
  const TemporaryDirectory dir;
  std::printf(
      "plant: %d cells on DDS domain %d (%s, cell-1 sweeps every %.2f s, the others every %.1f s); "
      "load average %s\n",
      options.cells, options.domain, options.sensor.c_str(), options.change_sweep_period,
      options.sweep_period, load_average().c_str());
  std::fflush(stdout);
  std::vector<std::uint64_t> drops{udp_receive_drops()};  // at each phase's start
  const std::int64_t launched_ns = now_ns();
  const auto daemons = start_daemons(options, program, dir.path());
  const dds::Participant participant(static_cast<std::uint32_t>(options.domain));
  transport::EnvironmentMonitor monitor(participant);
  MonitorView view;
  wait_for_every_cell(monitor, view, options);
  std::printf("every cell's first version at the monitor %.1f s after the daemons' start\n",
              static_cast<double>(now_ns() - launched_ns) / 1e9);

  drops.push_back(udp_receive_drops());
  Planners planners(options, self);
  const std::vector<std::uint64_t> joined = measure_discovery(options, planners);

  drops.push_back(udp_receive_drops());
  const transport::SceneEditWriter writer(participant, cell_name(0));
  if (!writer.wait_for_reader(std::chrono::seconds(static_cast<int>(options.timeout))))
    throw Error("no daemon's scene-edit reader matched");
  const std::size_t deltas_before = view.delta_bytes.size();
  print_latencies(inject_changes(options, planners, monitor, view, writer));
  std::this_thread::sleep_for(std::chrono::seconds(1));  // lets the planners report their last counts
  view.take(monitor, 0.1);
  print_foreign(options, planners, view, joined, deltas_before);
  print_memory(daemons, planners, options.cells);
  drops.push_back(udp_receive_drops());
  std::printf(
      "UDP datagrams dropped, receive buffer full: %llu while the daemons started, %llu while the "
      "planners joined, %llu during the changes\n",
      static_cast<unsigned long long>(drops[1] - drops[0]),
      static_cast<unsigned long long>(drops[2] - drops[1]),
      static_cast<unsigned long long>(drops[3] - drops[2]));
  std::printf("load average at the end: %s\n", load_average().c_str());
  return 0;
}

// Loopback unicast as in the tests, with room for every process's participant index (Cyclone's default
// stops at 10 participants per machine and domain).
std::string plant_dds_config(int cells) {
  return "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface address=\"127.0.0.1\"/>"
         "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto"
         "</ParticipantIndex><MaxAutoParticipantIndex>" +
         std::to_string(2 * cells + 10) +
         "</MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery></Domain>"
         "</CycloneDDS>";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::strcmp(argv[1], "--planner") == 0)
    return run_planner(static_cast<std::uint32_t>(std::stoul(argv[4])), argv[2]);
  CLI::App app{
      "cellmap bench plant: N cellmapd daemons on simulated cells, N planners following one cell each and a "
      "monitor following all, on one DDS domain on loopback; discovery time, delta latency, foreign traffic "
      "at planners, RSS"};
  Options options;
  app.add_option("--cells", options.cells, "daemons (cells) and planners")->check(CLI::Range(2, 200));
  app.add_option("--changes", options.changes, "boxes added to or removed from cell-1")
      ->check(CLI::Range(1, 10000));
  app.add_option("--sweep-period", options.sweep_period, "seconds between sweeps of every cell but cell-1")
      ->check(CLI::Range(0.0, 3600.0));
  app.add_option("--change-sweep-period", options.change_sweep_period, "seconds between sweeps of cell-1")
      ->check(CLI::Range(0.0, 3600.0));
  app.add_option("--sensor", options.sensor, "the default cell's sensor the daemons sweep with")
      ->check(CLI::IsMember({"os32c", "kinect", "realsense"}));
  app.add_option("--domain", options.domain, "DDS domain id")->check(CLI::Range(0, 232));
  app.add_option("--timeout", options.timeout, "seconds to wait for any one event")
      ->check(CLI::Range(1.0, 3600.0));
  CLI11_PARSE(app, argc, argv);
  ::setenv("CYCLONEDDS_URI", plant_dds_config(options.cells).c_str(),
           1);  // the daemons and planners inherit it
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  try {
    return run(options, self.string());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench plant: %s\n", e.what());
    return 1;
  }
}
