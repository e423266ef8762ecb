// SPDX-License-Identifier: Apache-2.0
// Publisher and subscribers in one process, on real Cyclone DDS participants (loopback only).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <future>
#include <mutex>
#include <set>
#include <sstream>
#include <string>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/transport/environment_monitor.hpp"
#include "cellmap/transport/environment_publisher.hpp"
#include "cellmap/transport/environment_subscriber.hpp"
#include "cellmap/transport/scene_edits.hpp"
#include "cellmap/transport/status_reader.hpp"
#include "loopback.hpp"
#include "scene_steps.hpp"
#include "support/dds_domains.hpp"
#include "support/test_credentials.hpp"
#include "support/test_support.hpp"

namespace cellmap::transport {
namespace {

using namespace std::chrono_literals;
using test::kPatience;

class TransportTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::use_loopback(); }
};

// Every callback of a subscriber, in order.
struct Recorded {
  std::mutex mutex;
  std::vector<std::pair<Environment, EnvironmentDelta>> calls;
  EnvironmentSubscriber::Callback callback() {
    return [this](const Environment& env, const EnvironmentDelta& delta) {
      const std::lock_guard<std::mutex> lock(mutex);
      calls.emplace_back(env, delta);
    };
  }
};

// Publishes versions first..last of the test sequence, each with its delta.
Environment publish_versions(EnvironmentPublisher& publisher, Environment env, std::uint64_t last) {
  for (std::uint64_t v = env.version() + 1; v <= last; ++v) {
    const Environment next = test::next_environment(env, v, static_cast<std::int64_t>(v));
    publisher.publish(next, diff(env, next));
    env = next;
  }
  return env;
}

TEST_F(TransportTest, SubscriberReceivesEveryVersionWithItsDelta) {
  dds::Participant daemon(test::domain::kEveryVersion);
  dds::Participant planner(test::domain::kEveryVersion);
  EnvironmentPublisher publisher(daemon, "cell-a");
  Recorded recorded;
  EnvironmentSubscriber subscriber(planner, "cell-a", recorded.callback());
  ASSERT_TRUE(publisher.wait_for_subscribers(1, kPatience));

  Environment env = test::next_environment(Environment("cell-a"), 1, 1);
  publisher.publish(env);
  ASSERT_TRUE(subscriber.wait_for_version(1, kPatience)) << subscriber.last_error();
  const Environment last = publish_versions(publisher, env, 12);
  ASSERT_TRUE(subscriber.wait_for_version(12, kPatience)) << subscriber.last_error();

  EXPECT_EQ(*subscriber.environment(), last);
  const std::lock_guard<std::mutex> lock(recorded.mutex);
  // Every call continues the previous one, and each delta after the first carries exactly one box change.
  Environment previous("cell-a");
  for (const auto& [seen, delta] : recorded.calls) {
    EXPECT_EQ(apply(previous, delta), seen);
    if (previous.version() > 0) {
      EXPECT_EQ(delta.added.size() + delta.modified.size(), 1u) << "version " << seen.version();
      EXPECT_TRUE(delta.removed.empty());
    }
    previous = seen;
  }
  EXPECT_EQ(previous, last);
  EXPECT_TRUE(subscriber.last_error().empty()) << subscriber.last_error();
}

TEST_F(TransportTest, LateJoinerGetsTheCurrentEnvironmentAtOnce) {
  dds::Participant daemon(test::domain::kLateJoiner);
  EnvironmentPublisher publisher(daemon, "cell-a");
  Environment env = test::next_environment(Environment("cell-a"), 1, 1);
  publisher.publish(env);
  const Environment last = publish_versions(publisher, env, 10);

  dds::Participant planner(test::domain::kLateJoiner);
  Recorded recorded;
  EnvironmentSubscriber subscriber(planner, "cell-a", recorded.callback());
  ASSERT_TRUE(subscriber.wait_for_version(10, kPatience)) << subscriber.last_error();
  EXPECT_EQ(*subscriber.environment(), last);
  const std::lock_guard<std::mutex> lock(recorded.mutex);
  ASSERT_EQ(recorded.calls.size(), 1u);  // the snapshot of 10, not a replay of old versions
  EXPECT_EQ(recorded.calls[0].second.from_version, 0u);
  EXPECT_EQ(recorded.calls[0].second.added.size(), last.boxes().size());
}

TEST_F(TransportTest, VersionPublishedWholeIsTakenAsASnapshot) {
  dds::Participant daemon(test::domain::kWholeVersion);
  dds::Participant planner(test::domain::kWholeVersion);
  EnvironmentPublisher publisher(daemon, "cell-a");
  Recorded recorded;
  EnvironmentSubscriber subscriber(planner, "cell-a", recorded.callback());
  const Environment v1 = test::next_environment(Environment("cell-a"), 1, 1);
  publisher.publish(v1);
  ASSERT_TRUE(subscriber.wait_for_version(1, kPatience));
  // Version 2 goes out whole (as after a restart): no delta 1 -> 2 exists.
  const Environment v2 = test::next_environment(v1, 2, 2);
  publisher.publish(v2);
  const Environment last = publish_versions(publisher, v2, 6);
  ASSERT_TRUE(subscriber.wait_for_version(6, kPatience)) << subscriber.last_error();
  EXPECT_EQ(*subscriber.environment(), last);
  EXPECT_GE(subscriber.stats().snapshots_applied, 2u);  // the first copy and version 2
  const std::lock_guard<std::mutex> lock(recorded.mutex);
  Environment previous("cell-a");
  for (const auto& [seen, delta] : recorded.calls) {
    EXPECT_EQ(apply(previous, delta), seen);
    previous = seen;
  }
}

TEST_F(TransportTest, SlowSubscriberLosesDeltasAndResyncs) {
  dds::Participant daemon(test::domain::kSlowSubscriber);
  dds::Participant planner(test::domain::kSlowSubscriber);
  EnvironmentPublisher publisher(daemon, "cell-a");
  std::mutex gate;
  std::unique_lock<std::mutex> hold(gate);  // the first callback blocks until the burst is out
  std::promise<void> entered;
  std::once_flag first;
  EnvironmentSubscriber subscriber(
      planner, "cell-a",
      [&](const Environment&, const EnvironmentDelta&) {
        std::call_once(first, [&] { entered.set_value(); });
        const std::lock_guard<std::mutex> wait_for_burst(gate);
      },
      /*delta_depth=*/2);
  const Environment v1 = test::next_environment(Environment("cell-a"), 1, 1);
  publisher.publish(v1);
  ASSERT_EQ(entered.get_future().wait_for(kPatience), std::future_status::ready);
  // The receiving thread is now stuck in the callback of version 1 while 29 versions go out.
  const Environment last = publish_versions(publisher, v1, 30);
  hold.unlock();
  ASSERT_TRUE(subscriber.wait_for_version(30, kPatience)) << subscriber.last_error();
  EXPECT_EQ(*subscriber.environment(), last);
  const TrackerStats stats = subscriber.stats();
  EXPECT_GE(stats.gaps, 1u);
  EXPECT_GE(stats.snapshots_applied, 2u)
      << "deltas applied " << stats.deltas_applied << ", gaps " << stats.gaps;
}

TEST_F(TransportTest, PublisherRestartDoesNotRemoveBoxes) {
  dds::Participant planner(test::domain::kPublisherRestart);
  Recorded recorded;
  EnvironmentSubscriber subscriber(planner, "cell-a", recorded.callback());
  Environment env = test::next_environment(Environment("cell-a"), 1, 1);
  {
    dds::Participant daemon(test::domain::kPublisherRestart);
    EnvironmentPublisher publisher(daemon, "cell-a");
    publisher.publish(env);
    env = publish_versions(publisher, env, 5);
    ASSERT_TRUE(subscriber.wait_for_version(5, kPatience));
  }  // the daemon goes away: writers deleted without disposing
  dds::Participant daemon(test::domain::kPublisherRestart);
  EnvironmentPublisher publisher(daemon, "cell-a");
  // A restarted daemon republishes what it persisted, then continues.
  publisher.publish(env);
  env = publish_versions(publisher, env, 8);
  ASSERT_TRUE(subscriber.wait_for_version(8, kPatience));
  EXPECT_EQ(*subscriber.environment(), env);
  const std::lock_guard<std::mutex> lock(recorded.mutex);
  for (const auto& [seen, delta] : recorded.calls) EXPECT_TRUE(delta.removed.empty()) << seen.version();
}

// Each cell in its own partition: a planner of cell-b is never matched with cell-a's writers, so none of
// cell-a's samples reach it; a monitor of every cell gets both.
TEST_F(TransportTest, CellsShareADomainWithoutMixing) {
  dds::Participant daemon(test::domain::kCellsShareADomain);
  dds::Participant planner(test::domain::kCellsShareADomain);
  EnvironmentPublisher cell_a(daemon, "cell-a");
  EnvironmentPublisher cell_b(daemon, "cell-b");
  EnvironmentSubscriber subscriber(planner, "cell-b");
  EnvironmentMonitor every_cell(planner, kEveryCell);
  ASSERT_TRUE(cell_a.wait_for_subscribers(1, kPatience)) << "the monitor of every cell did not match cell-a";
  ASSERT_TRUE(cell_b.wait_for_subscribers(2, kPatience));
  const Environment a = test::next_environment(Environment("cell-a"), 7, 1);
  const Environment b = test::next_environment(Environment("cell-b"), 3, 1);
  cell_a.publish(a);
  cell_b.publish(b);
  publish_versions(cell_a, a, 10);
  ASSERT_TRUE(subscriber.wait_for_version(3, kPatience));
  EXPECT_EQ(*subscriber.environment(), b);
  std::set<std::string> cells;
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (cells.size() < 2 && std::chrono::steady_clock::now() < deadline) {
    for (const EnvironmentMessage& m : every_cell.take(1s))
      cells.insert(m.index() == 0 ? std::get<Environment>(m).cell() : std::get<EnvironmentDelta>(m).cell);
  }
  EXPECT_EQ(cells, (std::set<std::string>{"cell-a", "cell-b"}));
  EXPECT_EQ(cell_a.subscribers_joined(), 1u) << "cell-b's planner matched cell-a's writers";
  EXPECT_EQ(subscriber.stats().other_cells, 0u);
  EXPECT_THROW(EnvironmentSubscriber(planner, "cell*"), Error);  // a pattern is not a cell
}

TEST_F(TransportTest, MonitorSeesSnapshotsAndDeltasInOrder) {
  dds::Participant daemon(test::domain::kMonitor);
  dds::Participant watcher(test::domain::kMonitor);
  EnvironmentPublisher publisher(daemon, "cell-a");
  EnvironmentMonitor monitor(watcher);
  ASSERT_TRUE(publisher.wait_for_subscribers(1, kPatience));
  const Environment v1 = test::next_environment(Environment("cell-a"), 1, 1);
  publisher.publish(v1);
  std::vector<EnvironmentMessage> seen;
  // The snapshot reader keeps only the newest snapshot per cell: publish the next version once one is seen.
  auto take_until = [&](std::size_t count) {
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while (seen.size() < count && std::chrono::steady_clock::now() < deadline) {
      for (auto& m : monitor.take(1s)) seen.push_back(std::move(m));
    }
    return seen.size();
  };
  ASSERT_EQ(take_until(2), 2u);
  const Environment v2 = publish_versions(publisher, v1, 2);
  ASSERT_EQ(take_until(4), 4u);
  publish_versions(publisher, v2, 3);
  ASSERT_EQ(take_until(6), 6u);
  // Per version a delta (version 1 whole, from 0) and a snapshot; the two topics may interleave differently.
  auto version_of = [](const EnvironmentMessage& m) {
    return m.index() == 0 ? std::get<Environment>(m).version() : std::get<EnvironmentDelta>(m).to_version;
  };
  std::stable_sort(seen.begin(), seen.end(), [&](const auto& a, const auto& b) {
    return std::make_pair(version_of(a), a.index() == 0) < std::make_pair(version_of(b), b.index() == 0);
  });
  for (std::uint64_t v = 1; v <= 3; ++v) {
    const auto& delta = std::get<EnvironmentDelta>(seen[2 * (v - 1)]);
    EXPECT_EQ(delta.from_version, v - 1);
    EXPECT_EQ(delta.to_version, v);
    EXPECT_EQ(std::get<Environment>(seen[2 * (v - 1) + 1]).version(), v);
  }
  EXPECT_EQ(monitor.rejected(), 0u);
}

TEST_F(TransportTest, SceneEditsArriveIntact) {
  dds::Participant simulator(test::domain::kSceneEdits);
  dds::Participant tool(test::domain::kSceneEdits);
  SceneEditReader reader(simulator, "sim-cell");
  SceneEditWriter writer(tool, kEveryCell);  // edits for every simulating daemon
  ASSERT_TRUE(writer.wait_for_reader(kPatience));
  SceneEdit edit;
  edit.kind = SceneEdit::Kind::kAddBox;
  edit.name = "obstacle-1";
  edit.center = {0.5, -0.25, 0.125};
  edit.half_extents = {0.1, 0.2, 0.3};
  edit.yaw = 0.75;
  writer.write(edit);
  SceneEdit move = edit;
  move.kind = SceneEdit::Kind::kMove;
  move.center = {1, 2, 3};
  writer.write(move);
  EXPECT_TRUE(writer.wait_for_acks(kPatience));
  std::vector<SceneEdit> received;
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (received.size() < 2 && std::chrono::steady_clock::now() < deadline) {
    for (auto& e : reader.take(1s)) received.push_back(e);
  }
  ASSERT_EQ(received.size(), 2u);
  EXPECT_EQ(received[0].kind, SceneEdit::Kind::kAddBox);
  EXPECT_EQ(received[0].name, "obstacle-1");
  EXPECT_EQ(received[0].center, edit.center);
  EXPECT_EQ(received[0].half_extents, edit.half_extents);
  EXPECT_EQ(received[0].yaw, 0.75);
  EXPECT_EQ(received[1].kind, SceneEdit::Kind::kMove);
  EXPECT_EQ(received[1].center, move.center);
  SceneEdit nameless;
  EXPECT_THROW(writer.write(nameless), Error);
  SceneEdit for_one_cell = edit;
  for_one_cell.cell = "sim-cell";
  EXPECT_THROW(writer.write(for_one_cell), Error);  // the every-cell writer writes edits for every cell only
}

TEST_F(TransportTest, StatusReachesALateReader) {
  dds::Participant daemon(test::domain::kStatusLateReader);
  EnvironmentPublisher publisher(daemon, "cell-a");
  CellStatus status;
  status.cell = "cell-a";
  status.state = "running";
  status.sensors = {{"kinect_v2", "streaming"}, {"os32c", "no device"}};
  status.last_sweep_ns = 1'700'000'000'000'000'000;
  status.sweeps = 42;
  status.dropped_frames = 3;
  status.boxes = 17;
  status.version = 9;
  publisher.publish_status(status);
  EXPECT_THROW(publisher.publish_status(CellStatus{}), Error);  // another cell
  dds::Participant monitor(test::domain::kStatusLateReader);
  StatusReader reader(monitor);
  std::vector<CellStatus> reports;
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (reports.empty() && std::chrono::steady_clock::now() < deadline) reports = reader.take(1s);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].state, "running");
  ASSERT_EQ(reports[0].sensors.size(), 2u);
  EXPECT_EQ(reports[0].sensors[1].name, "os32c");
  EXPECT_EQ(reports[0].sensors[1].state, "no device");
  EXPECT_EQ(reports[0].last_sweep_ns, status.last_sweep_ns);
  EXPECT_EQ(reports[0].sweeps, 42u);
  EXPECT_EQ(reports[0].dropped_frames, 3u);
  EXPECT_EQ(reports[0].boxes, 17u);
  EXPECT_EQ(reports[0].version, 9u);
}

TEST_F(TransportTest, PublisherRefusesWrongVersionsAndCells) {
  dds::Participant daemon(test::domain::kPublisherRefuses);
  EnvironmentPublisher publisher(daemon, "cell-a");
  EXPECT_THROW(publisher.publish(Environment("cell-a")), Error);  // version 0
  EXPECT_THROW(publisher.publish(Environment("cell-b", 1, 0, {})), Error);
  const Environment v2("cell-a", 2, 0, {});
  publisher.publish(v2);
  EXPECT_THROW(publisher.publish(v2), Error);
  const Environment v3("cell-a", 3, 0, {});
  EnvironmentDelta wrong = diff(v2, v3);
  wrong.to_version = 4;
  EXPECT_THROW(publisher.publish(v3, wrong), Error);
  EXPECT_THROW(dds::Participant(100000), Error);  // domain ids end at 232
}

// Cyclone DDS gives every participant of a process on a domain the first one's DDS Security setting, so a
// second setting on the same domain must be refused rather than silently replaced.
TEST_F(TransportTest, AProcessTakesOneSecuritySettingPerDomain) {
  const test::TestCredentials credentials("guarded", 124);
  const auto refused = [](const std::function<void()>& join) {
    try {
      join();
    } catch (const Error& e) {
      return std::string(e.what()).find("one security setting per domain and process") != std::string::npos;
    }
    return false;
  };
  {
    const dds::Participant planner(test::domain::kSecuritySetting, credentials.as(security::Role::kPlanner));
    const dds::Participant same_setting(test::domain::kSecuritySetting,
                                        credentials.as(security::Role::kPlanner));
    EXPECT_TRUE(refused([] { dds::Participant plain(test::domain::kSecuritySetting); }));
    EXPECT_TRUE(refused([&] {
      dds::Participant tool(test::domain::kSecuritySetting, credentials.as(security::Role::kTool));
    }));
    const dds::Participant other_domain(test::domain::kSecuritySettingOther);
  }
  // Once the secured participants are gone the domain takes any setting again.
  const dds::Participant plain(test::domain::kSecuritySetting);
  EXPECT_FALSE(plain.credentials());
}

// What Cyclone DDS runs a domain with, as its configuration trace says: "config: <setting>: <value>
// {<source>}".
std::string traced_config(int domain, const std::string& user_settings, const std::string& setting) {
  const test::TempDir dir("cellmap-cyclone-trace");
  const std::string trace = (dir.path() / "trace.log").string();
  const char* before = std::getenv("CYCLONEDDS_URI");
  const std::string kept = before ? before : "";
  ::setenv("CYCLONEDDS_URI",
           ("<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface address=\"127.0.0.1\"/>"
            "</Interfaces></General><Tracing><Category>config</Category><OutputFile>" +
            trace + "</OutputFile></Tracing>" + user_settings + "</Domain></CycloneDDS>")
               .c_str(),
           1);
  { const dds::Participant participant(static_cast<std::uint32_t>(domain)); }
  ::setenv("CYCLONEDDS_URI", kept.c_str(), 1);
  std::istringstream lines(read_file(trace));
  for (std::string line; std::getline(lines, line);) {
    const std::size_t at = line.find("config: " + setting + ": ");
    if (at != std::string::npos) return line.substr(at + std::string("config: ").size() + setting.size() + 2);
  }
  return "(not traced)";
}

TEST(DomainTest, EveryDomainCapsTheSampleSizeAndKeepsTheUsersConfiguration) {
  // Ours is the first configuration source ({0}), the user's CYCLONEDDS_URI the second ({1}).
  EXPECT_EQ(traced_config(test::domain::kSampleSizeCap, "", "Domain/Internal/MaxSampleSize/#text"),
            "256 MiB {0}");
  EXPECT_EQ(
      traced_config(test::domain::kSampleSizeCap, "", "Domain/General/Interfaces/NetworkInterface[@address]"),
      "127.0.0.1 {1}");
  // A user who needs larger samples (a camera of 16 million points of 32 bytes) says so and wins.
  EXPECT_EQ(traced_config(test::domain::kSampleSizeUserCap,
                          "<Internal><MaxSampleSize>512 MiB</MaxSampleSize></Internal>",
                          "Domain/Internal/MaxSampleSize/#text"),
            "512 MiB {0,1}");
}

}  // namespace
}  // namespace cellmap::transport
