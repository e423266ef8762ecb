// SPDX-License-Identifier: Apache-2.0
// cellmap bench dds: what a one-box change costs a planner over DDS, ours (a delta through the planner client
// library) against the anchor (the full 200-box snapshot each version, read by a plain snapshot reader),
// measured in the same run with the subscriber in a second process on loopback.
//
// Latency is one way, publisher write -> subscriber callback, on the shared CLOCK_MONOTONIC; each change is
// published once the previous one arrived (no queueing). Bytes are the serialized sample (wire_size).
//
// The cost of DDS Security, in the same run: the delta path again with both processes secured (credentials
// made by the library of `cellmap security init`), data signed (AES-GMAC) and encrypted (AES-GCM), against
// the plain one; latency, and the bytes that cross the loopback interface per change (every RTPS message:
// data, heartbeats, acknowledgements; /sys/class/net/lo, so run it where nothing else uses loopback, e.g. in
// a network namespace).
#include <benchmark/benchmark.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/security/cell_setup.hpp"
#include "cellmap/transport/environment_publisher.hpp"
#include "cellmap/transport/environment_subscriber.hpp"
#include "ratio_report.hpp"
#include "subscriber_arrivals.hpp"
#include "wire.hpp"       // the transport stage's private wire types: the anchor writes raw snapshots
#include "wire_size.hpp"  // internal to the transport stage

namespace {

using namespace cellmap;
using Clock = std::chrono::steady_clock;  // CLOCK_MONOTONIC on Linux: comparable across processes

constexpr int kBoxes = 200;
constexpr const char* kCell = "bench";
using bench::Arrival;
using bench::kLoopbackConfig;
using bench::now_ns;

void report(std::uint64_t version) {
  bench::report_arrival(version);
}

Environment cell_with_boxes(std::uint64_t version) {
  std::vector<Box> boxes;
  for (int i = 0; i < kBoxes; ++i) {
    Box box;
    box.id = static_cast<std::uint64_t>(i + 1);
    box.center = {0.1 * (i % 20), 0.1 * (i / 20), 0.5};
    box.half_extents = {0.04, 0.04, 0.2};
    box.points = 500;
    boxes.push_back(box);
  }
  return Environment(kCell, version, 0, boxes);
}

// The next version: one box moved by a millimetre.
Environment one_box_moved(const Environment& env) {
  std::vector<Box> boxes = env.boxes();
  boxes[env.version() % boxes.size()].center.z() += 0.001;
  return Environment(kCell, env.version() + 1, 0, std::move(boxes));
}

// Credentials for the secured runs, one set per data protection, removed at exit.
class BenchCredentials {
 public:
  BenchCredentials() {
    std::string pattern = (std::filesystem::temp_directory_path() / "cellmap-bench-dds-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) std::abort();
    directory_ = pattern;
    write(signed_directory(), kSignedDomain, security::DataProtection::kSign);
    write(encrypted_directory(), kEncryptedDomain, security::DataProtection::kEncrypt);
  }
  ~BenchCredentials() {
    std::error_code ec;
    std::filesystem::remove_all(directory_, ec);
  }
  [[nodiscard]] std::filesystem::path signed_directory() const { return directory_ / "signed"; }
  [[nodiscard]] std::filesystem::path encrypted_directory() const { return directory_ / "encrypted"; }
  static constexpr std::uint32_t kSignedDomain = 142;
  static constexpr std::uint32_t kEncryptedDomain = 143;

 private:
  static void write(const std::filesystem::path& directory, std::uint32_t domain,
                    security::DataProtection data) {
    security::CellSetup setup;
    setup.directory = directory;
    setup.cell = kCell;
    setup.domain = domain;
    setup.valid_from = std::chrono::system_clock::now() - std::chrono::hours(1);
    setup.valid_until = setup.valid_from + std::chrono::hours(24);
    setup.ca_valid_until = setup.valid_until;
    setup.ca = {directory.string() + "-ca", "bench passphrase"};
    setup.grants = transport::role_grants(setup.cell);
    setup.data_protection = data;
    security::write_cell_credentials(setup);
  }
  std::filesystem::path directory_;
};

BenchCredentials& credentials() {
  static BenchCredentials made;
  return made;
}

// Bytes sent over the loopback interface so far (0 where the counter cannot be read).
std::uint64_t loopback_bytes() {
  std::ifstream in("/sys/class/net/lo/statistics/tx_bytes");
  std::uint64_t bytes = 0;
  in >> bytes;
  return bytes;
}

std::optional<security::Setting> secured_as(const std::string& directory, security::Role role) {
  if (directory.empty()) return std::nullopt;
  return security::Setting{directory, role};
}

// --- the subscriber process -------------------------------------------------------------------------------

int run_delta_subscriber(std::uint32_t domain, const std::string& security_directory) {
  const dds::Participant participant(domain, secured_as(security_directory, security::Role::kPlanner));
  transport::EnvironmentSubscriber subscriber(
      participant, kCell, [](const Environment& env, const EnvironmentDelta&) { report(env.version()); });
  ::pause();  // killed by the parent
  return 0;
}

int run_snapshot_subscriber(std::uint32_t domain) {
  const dds::Participant participant(domain);
  const dds::Topic topic(participant, &cellmap_msg_Environment_desc, transport::kEnvironmentTopic);
  const dds::Reader reader(participant, topic, transport::in_cell(transport::environment_qos(), kCell));
  dds::WaitSet waitset(participant);
  waitset.attach(reader);
  for (;;) {
    waitset.wait(std::chrono::seconds(1));
    reader.take_all([](const void* sample, const dds_sample_info_t&) {
      // Converted as a planner would before using it.
      const Environment env =
          transport::wire::from_wire(*static_cast<const cellmap_msg_Environment*>(sample));
      report(env.version());
    });
  }
}

// --- the publisher side -----------------------------------------------------------------------------------

class SubscriberProcess {
 public:
  /// With a security directory, the subscriber joins as its planner.
  SubscriberProcess(const char* mode, std::uint32_t domain, const std::string& security_directory = "")
      : child_({"cellmap-bench-dds", "--subscriber", mode, std::to_string(domain), security_directory}) {}
  /// The next arrival at or past `version`, or nullopt after 10 s.
  std::optional<Arrival> wait_for(std::uint64_t version) {
    for (;;) {
      pollfd p{child_.in_fd(), POLLIN, 0};
      if (::poll(&p, 1, 10'000) <= 0) return std::nullopt;
      Arrival arrival;
      if (::read(child_.in_fd(), &arrival, sizeof arrival) != sizeof arrival) return std::nullopt;
      if (arrival.version >= version) return arrival;
    }
  }

 private:
  bench::ReportingChild child_;
};

// p50 and p99 one-way latency (us) of each benchmark, kept for the ratio lines printed after the run:
// on a shared machine the mean time per change is dominated by scheduling outliers, the median is not.
std::map<std::string, std::pair<double, double>>& percentiles() {
  static std::map<std::string, std::pair<double, double>> by_benchmark;
  return by_benchmark;
}

void set_percentiles(benchmark::State& state, const std::string& name, std::vector<double> latencies_us) {
  if (latencies_us.empty()) return;
  std::sort(latencies_us.begin(), latencies_us.end());
  auto at = [&](double q) { return latencies_us[static_cast<std::size_t>(q * (latencies_us.size() - 1))]; };
  state.counters["p50_us"] = at(0.50);
  state.counters["p99_us"] = at(0.99);
  percentiles()[name] = {at(0.50), at(0.99)};
}

// Runs the timed loop: publish(next) then wait until the subscriber reports it.
template <class Publish>
void measure(benchmark::State& state, const std::string& name, SubscriberProcess& subscriber, Environment env,
             Publish publish) {
  std::vector<double> latencies_us;
  for (auto _ : state) {
    const Environment next = one_box_moved(env);
    const std::int64_t sent = now_ns();
    publish(env, next);
    const std::optional<Arrival> arrival = subscriber.wait_for(next.version());
    if (!arrival) {
      state.SkipWithError("the subscriber did not report the version within 10 s");
      return;
    }
    latencies_us.push_back(static_cast<double>(arrival->received_ns - sent) / 1e3);
    env = next;
  }
  set_percentiles(state, name, latencies_us);
}

// Loopback bytes per change of each delta benchmark, kept for the security ratio lines.
std::map<std::string, double>& loopback_bytes_per_change() {
  static std::map<std::string, double> by_benchmark;
  return by_benchmark;
}

// The delta path: publisher here, planner client in the subscriber process, both secured from `directory`
// (as daemon and planner) unless it is empty.
void delta_one_box_change(benchmark::State& state, const std::string& name, std::uint32_t domain,
                          const std::string& directory) {
  SubscriberProcess subscriber("delta", domain, directory);
  const dds::Participant participant(domain, secured_as(directory, security::Role::kDaemon));
  transport::EnvironmentPublisher publisher(participant, kCell);
  const Environment first = cell_with_boxes(1);
  publisher.publish(first);
  if (!subscriber.wait_for(1)) return state.SkipWithError("the subscriber never got version 1");
  const std::uint64_t bytes_before = loopback_bytes();
  measure(state, name, subscriber, first, [&](const Environment& before, const Environment& after) {
    publisher.publish(after, diff(before, after));
  });
  state.counters["bytes_per_change"] =
      static_cast<double>(transport::wire_size(diff(first, one_box_moved(first))));
  const double loopback =
      static_cast<double>(loopback_bytes() - bytes_before) / static_cast<double>(state.iterations());
  state.counters["loopback_bytes_per_change"] = loopback;
  loopback_bytes_per_change()[name] = loopback;
}

void BM_DeltaOneBoxChange(benchmark::State& state) {
  delta_one_box_change(state, "BM_DeltaOneBoxChange", 140, "");
}

void BM_DeltaOneBoxChangeSigned(benchmark::State& state) {
  delta_one_box_change(state, "BM_DeltaOneBoxChangeSigned", BenchCredentials::kSignedDomain,
                       credentials().signed_directory().string());
}

void BM_DeltaOneBoxChangeEncrypted(benchmark::State& state) {
  delta_one_box_change(state, "BM_DeltaOneBoxChangeEncrypted", BenchCredentials::kEncryptedDomain,
                       credentials().encrypted_directory().string());
}

void BM_FullSnapshotEachChange(benchmark::State& state) {
  SubscriberProcess subscriber("snapshot", 141);
  const dds::Participant participant(141);
  const dds::Topic topic(participant, &cellmap_msg_Environment_desc, transport::kEnvironmentTopic);
  dds::Qos qos = transport::in_cell(transport::environment_qos(), kCell);
  qos.autodispose(false);
  const dds::Writer writer(participant, topic, qos);
  const Environment first = cell_with_boxes(1);
  writer.write(transport::wire::EnvironmentSample(first).get());
  if (!subscriber.wait_for(1)) return state.SkipWithError("the subscriber never got version 1");
  measure(state, "BM_FullSnapshotEachChange", subscriber, first,
          [&](const Environment&, const Environment& after) {
            writer.write(transport::wire::EnvironmentSample(after).get());
          });
  state.counters["bytes_per_change"] = static_cast<double>(transport::wire_size(first));
}

BENCHMARK(BM_DeltaOneBoxChange)->Iterations(3000)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FullSnapshotEachChange)->Iterations(3000)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DeltaOneBoxChangeSigned)->Iterations(3000)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DeltaOneBoxChangeEncrypted)->Iterations(3000)->UseRealTime()->Unit(benchmark::kMicrosecond);

// "ratio dds security cost, ...": secured over plain, both measured above (above 1: what security costs).
void print_security_costs() {
  const auto plain = percentiles().find("BM_DeltaOneBoxChange");
  const auto plain_bytes = loopback_bytes_per_change().find("BM_DeltaOneBoxChange");
  for (const char* kind : {"Signed", "Encrypted"}) {
    const std::string name = std::string("BM_DeltaOneBoxChange") + kind;
    const auto secured = percentiles().find(name);
    if (plain == percentiles().end() || secured == percentiles().end()) continue;
    const char* label = kind[0] == 'S' ? "signed" : "encrypted";
    std::printf("ratio dds security cost, one-box change latency p50, %s: %.2fx (%.1f us vs plain %.1f us)\n",
                label, secured->second.first / plain->second.first, secured->second.first,
                plain->second.first);
    std::printf("ratio dds security cost, one-box change latency p99, %s: %.2fx (%.1f us vs plain %.1f us)\n",
                label, secured->second.second / plain->second.second, secured->second.second,
                plain->second.second);
    const auto bytes = loopback_bytes_per_change().find(name);
    if (plain_bytes != loopback_bytes_per_change().end() && bytes != loopback_bytes_per_change().end() &&
        plain_bytes->second > 0) {
      std::printf(
          "ratio dds security cost, loopback bytes per one-box change, %s: %.2fx (%.0f B vs plain %.0f B)\n",
          label, bytes->second / plain_bytes->second, bytes->second, plain_bytes->second);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  ::setenv("CYCLONEDDS_URI", kLoopbackConfig, 0);  // keep the caller's configuration if there is one
  if (argc == 5 && std::strcmp(argv[1], "--subscriber") == 0) {
    try {
      const auto domain = static_cast<std::uint32_t>(std::stoul(argv[3]));
      return std::strcmp(argv[2], "delta") == 0 ? run_delta_subscriber(domain, argv[4])
                                                : run_snapshot_subscriber(domain);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "cellmap-bench-dds subscriber: %s\n", e.what());
      return 1;
    }
  }
  const int status = cellmap::bench::run_and_report(
      argc, argv,
      {{"dds one-box change latency", "BM_DeltaOneBoxChange/iterations:3000/real_time",
        "BM_FullSnapshotEachChange/iterations:3000/real_time"}});
  const Environment first = cell_with_boxes(1);
  const std::size_t delta_bytes = transport::wire_size(diff(first, one_box_moved(first)));
  const std::size_t snapshot_bytes = transport::wire_size(first);
  const auto ours = percentiles().find("BM_DeltaOneBoxChange");
  const auto anchor = percentiles().find("BM_FullSnapshotEachChange");
  if (ours != percentiles().end() && anchor != percentiles().end()) {
    std::printf("ratio dds one-box change latency p50: %.2fx (ours %.1f us, anchor %.1f us)\n",
                anchor->second.first / ours->second.first, ours->second.first, anchor->second.first);
    std::printf("ratio dds one-box change latency p99: %.2fx (ours %.1f us, anchor %.1f us)\n",
                anchor->second.second / ours->second.second, ours->second.second, anchor->second.second);
  }
  std::printf("ratio dds bytes per one-box change (%d boxes): %.2fx (delta %zu B, snapshot %zu B)\n", kBoxes,
              static_cast<double>(snapshot_bytes) / static_cast<double>(delta_bytes), delta_bytes,
              snapshot_bytes);
  print_security_costs();
  return status;
}
