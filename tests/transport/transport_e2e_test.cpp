// SPDX-License-Identifier: Apache-2.0
// Publisher, planner subscriber and `cellmap echo` as separate processes on loopback DDS.
#include <gtest/gtest.h>

#include <stdlib.h>
#include "support/test_support.hpp"

#include <filesystem>
#include <future>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <thread>

#include "cellmap.h"
#include "cellmap/environment/version_store.hpp"
#include "cellmap/transport/environment_publisher.hpp"
#include "cellmap/transport/environment_subscriber.hpp"
#include "child_process.hpp"
#include "loopback.hpp"
#include "support/dds_domains.hpp"

namespace cellmap::transport {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using nlohmann::json;
constexpr auto kPatience = 60s;

std::vector<std::string> helper(int domain, const fs::path& state, int versions, int interval_ms) {
  return {TRANSPORT_PUBLISHER_HELPER, std::to_string(domain), state.string(), std::to_string(versions),
          std::to_string(interval_ms)};
}

// Reads the helper's lines until one starts with `prefix`; records every "publishing V". Returns V of it.
std::uint64_t read_until(test::ChildProcess& child, const std::string& prefix,
                         std::vector<std::uint64_t>& published) {
  for (;;) {
    const std::optional<std::string> line = child.read_line(kPatience);
    if (!line) throw std::runtime_error("helper said nothing for a minute (waiting for '" + prefix + "')");
    const auto space = line->find(' ');
    const std::uint64_t version = std::stoull(line->substr(space + 1));
    if (line->rfind("publishing", 0) == 0) published.push_back(version);
    if (line->rfind(prefix, 0) == 0) return version;
  }
}

class TransportE2eTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::use_loopback(); }
};

TEST_F(TransportE2eTest, LateJoinerInAnotherProcessGetsTheLatestSnapshot) {
  test::TempDir dir;
  test::ChildProcess daemon(helper(test::domain::kLateJoinerProcess, dir.path(), 10, 0));
  std::vector<std::uint64_t> published;
  const std::uint64_t last = read_until(daemon, "done", published);
  ASSERT_EQ(last, 10u);

  // Both joiners arrive after ten versions: the library copy and `cellmap echo`.
  test::ChildProcess echo({CELLMAP_TOOL, "echo", "--domain", std::to_string(test::domain::kLateJoinerProcess),
                           "--count", "11", "--timeout", "60"});
  const dds::Participant planner(test::domain::kLateJoinerProcess);
  std::atomic<int> calls{0};
  EnvironmentSubscriber subscriber(planner, "cell-e2e",
                                   [&](const Environment&, const EnvironmentDelta&) { ++calls; });
  ASSERT_TRUE(subscriber.wait_for_version(10, kPatience)) << subscriber.last_error();
  EXPECT_EQ(subscriber.environment()->version(), 10u);
  EXPECT_EQ(calls.load(), 1);  // straight to version 10, no replay

  // echo: the ten deltas (the history keeps 16) and the snapshot of 10. The two topics arrive independently,
  // so only the order within each is fixed.
  std::vector<json> deltas;
  std::vector<json> snapshots;
  while (auto line = echo.read_line(kPatience)) {
    const json message = json::parse(*line);
    (message["type"] == "delta" ? deltas : snapshots).push_back(message);
  }
  ASSERT_EQ(snapshots.size(), 1u);
  EXPECT_EQ(snapshots[0]["cell"], "cell-e2e");
  EXPECT_EQ(snapshots[0]["version"], 10);
  EXPECT_EQ(snapshots[0]["boxes"].size(), subscriber.environment()->boxes().size());
  ASSERT_EQ(deltas.size(), 10u);
  for (std::size_t i = 0; i < deltas.size(); ++i) {
    EXPECT_EQ(deltas[i]["cell"], "cell-e2e");
    EXPECT_EQ(deltas[i]["version"], i + 1);
    EXPECT_EQ(deltas[i]["from_version"], i);
    EXPECT_EQ(deltas[i]["added"].size() + deltas[i]["modified"].size(), 1u);
    EXPECT_TRUE(deltas[i]["removed"].empty());
  }
  EXPECT_EQ(test::exit_code(echo.wait()), 0);
  daemon.signal(SIGTERM);
  EXPECT_EQ(test::exit_code(daemon.wait()), 0);
}

TEST_F(TransportE2eTest, SubscriberThatFallsBehindResyncsFromTheSnapshot) {
  test::TempDir dir;
  const dds::Participant planner(test::domain::kFallsBehind);
  std::mutex gate;
  std::unique_lock<std::mutex> hold(gate);  // the first callback blocks until the daemon is done
  std::promise<void> entered;
  std::once_flag first;
  EnvironmentSubscriber subscriber(
      planner, "cell-e2e",
      [&](const Environment&, const EnvironmentDelta&) {
        std::call_once(first, [&] { entered.set_value(); });
        const std::lock_guard<std::mutex> wait_for_daemon(gate);
      },
      /*delta_depth=*/2);
  test::ChildProcess daemon(helper(test::domain::kFallsBehind, dir.path(), 1, 0));
  std::vector<std::uint64_t> published;
  read_until(daemon, "done", published);
  ASSERT_EQ(entered.get_future().wait_for(kPatience), std::future_status::ready);
  daemon.signal(SIGTERM);
  daemon.wait();
  // While the planner's callback is stuck, a second daemon run publishes 40 versions; its reader keeps 2.
  test::ChildProcess busy(helper(test::domain::kFallsBehind, dir.path(), 40, 0));
  const std::uint64_t last = read_until(busy, "done", published);
  hold.unlock();
  ASSERT_TRUE(subscriber.wait_for_version(last, kPatience)) << subscriber.last_error();
  busy.signal(SIGTERM);
  busy.wait();
  EXPECT_EQ(*subscriber.environment(), VersionStore(dir.path(), "cell-e2e").recovered().environment);
  EXPECT_GE(subscriber.stats().gaps, 1u);
  EXPECT_GE(subscriber.stats().snapshots_applied, 2u);
}

// Without DDS Security anyone on the domain may publish a cell's environment. A forged snapshot far ahead (a
// version near 2^64) must not freeze a planner: one that follows the cell refuses it (a jump beyond 2^32),
// and one that joins while the forger's snapshot is the only one on the topic takes it and then follows the
// daemon back once the daemon's versions go on below it, past the forger's snapshot delivered again.
TEST_F(TransportE2eTest, AForgedVersionNear2To64FreezesNoPlanner) {
  test::TempDir dir;
  const dds::Participant planner(test::domain::kForgedAhead);
  EnvironmentSubscriber following(planner, "cell-e2e");
  std::vector<std::uint64_t> published;
  auto daemon = std::make_unique<test::ChildProcess>(helper(test::domain::kForgedAhead, dir.path(), 3, 0));
  ASSERT_EQ(read_until(*daemon, "done", published), 3u);
  ASSERT_TRUE(following.wait_for_version(3, kPatience)) << following.last_error();
  daemon->signal(SIGTERM);
  daemon->wait();
  daemon.reset();

  const dds::Participant attacker(test::domain::kForgedAhead);
  EnvironmentPublisher forger(attacker, "cell-e2e");
  constexpr std::uint64_t kForged = std::numeric_limits<std::uint64_t>::max() - 8;
  forger.publish(Environment("cell-e2e", kForged, 0, {}));
  EnvironmentSubscriber joining(planner, "cell-e2e");
  ASSERT_TRUE(joining.wait_for_version(kForged, kPatience))
      << "the late joiner never got the forged snapshot";
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (following.stats().implausible == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(20ms);
  EXPECT_EQ(following.stats().implausible, 1u);
  EXPECT_EQ(following.environment()->version(), 3u) << "the following planner took the forged version";

  test::ChildProcess resumed(helper(test::domain::kForgedAhead, dir.path(), 5, 50));
  const std::uint64_t last = read_until(resumed, "done", published);
  const Environment persisted = VersionStore(dir.path(), "cell-e2e").recovered().environment;
  ASSERT_EQ(persisted.version(), last);
  for (const EnvironmentSubscriber* subscriber : {&following, &joining}) {
    while (subscriber->environment()->version() != last && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(20ms);
    EXPECT_EQ(*subscriber->environment(), persisted)
        << "a planner stayed at version " << subscriber->environment()->version();
  }
  EXPECT_EQ(following.stats().went_back, 0u);
  EXPECT_EQ(joining.stats().went_back, 1u);
  resumed.signal(SIGTERM);
  EXPECT_EQ(test::exit_code(resumed.wait()), 0);
}

TEST_F(TransportE2eTest, KilledPublisherResumesWithoutReuseOrRemoval) {
  test::TempDir dir;
  const dds::Participant planner(test::domain::kKilledPublisher);
  std::mutex mutex;
  std::vector<std::pair<Environment, EnvironmentDelta>> calls;
  EnvironmentSubscriber subscriber(planner, "cell-e2e",
                                   [&](const Environment& env, const EnvironmentDelta& delta) {
                                     const std::lock_guard<std::mutex> lock(mutex);
                                     calls.emplace_back(env, delta);
                                   });
  // A second reader of the deltas in the planner's participant: it tells when the killed daemons' writers
  // are gone for the planner.
  const dds::Topic delta_topic(planner, &cellmap_msg_EnvironmentDelta_desc, kEnvironmentDeltaTopic);
  const dds::Reader delta_watch(planner, delta_topic, environment_delta_qos(kDefaultDeltaDepth));
  test::ChildProcess echo(
      {CELLMAP_TOOL, "echo", "--domain", std::to_string(test::domain::kKilledPublisher), "--timeout", "600"});

  std::vector<std::uint64_t> published;
  std::mt19937 random(5);
  // Three daemons killed at random instants while publishing every 10 ms, then one that finishes.
  for (int run = 0; run < 3; ++run) {
    test::ChildProcess daemon(helper(test::domain::kKilledPublisher, dir.path(), 100000, 10));
    read_until(daemon, "publishing", published);
    std::this_thread::sleep_for(std::chrono::milliseconds(50 + random() % 200));
    daemon.signal(SIGKILL);
    daemon.wait();
    try {
      for (;;) read_until(daemon, "publishing", published);  // what it printed before dying
    } catch (const std::exception&) {
    }
  }
  // The killed daemons' writers expire at the planner when their 1 s lease (the loopback config) runs out;
  // the subscriber must not read that as "all boxes removed". Wait until it has happened.
  const auto lease_deadline = std::chrono::steady_clock::now() + kPatience;
  while (delta_watch.matched_writers() > 0 && std::chrono::steady_clock::now() < lease_deadline)
    std::this_thread::sleep_for(10ms);
  ASSERT_EQ(delta_watch.matched_writers(), 0u) << "the killed daemons' writers never expired";
  test::ChildProcess daemon(helper(test::domain::kKilledPublisher, dir.path(), 5, 10));
  const std::uint64_t last = read_until(daemon, "done", published);
  ASSERT_TRUE(subscriber.wait_for_version(last, kPatience)) << subscriber.last_error();

  // echo saw every daemon: each version it printed has one content only (a reused number would not). It must
  // have printed the last version before that daemon stops: it may start slower than the whole run (a
  // sanitizer build), and a version nobody publishes any more never reaches it.
  std::map<std::uint64_t, std::string> boxes_by_version;
  std::uint64_t highest = 0;
  const auto check_line = [&](const std::string& line) {
    const json message = json::parse(line);
    if (message["type"] != "snapshot") return;
    const std::uint64_t version = message["version"];
    const auto [it, fresh] = boxes_by_version.emplace(version, message["boxes"].dump());
    EXPECT_TRUE(fresh || it->second == message["boxes"].dump()) << "version " << version << " reused";
    highest = std::max(highest, version);
  };
  while (highest < last) {
    const auto line = echo.read_line(kPatience);
    if (!line) break;
    check_line(*line);
  }

  // No version number was published twice, by any of the four daemons.
  const std::set<std::uint64_t> unique(published.begin(), published.end());
  EXPECT_GT(published.size(), 8u);
  EXPECT_EQ(unique.size(), published.size());
  daemon.signal(SIGTERM);
  EXPECT_EQ(test::exit_code(daemon.wait()), 0);

  // The planner's copy is what the store persisted; it only ever grew, and no box was ever removed.
  const VersionStore store(dir.path(), "cell-e2e");
  EXPECT_EQ(*subscriber.environment(), store.recovered().environment);
  {
    const std::lock_guard<std::mutex> lock(mutex);
    ASSERT_FALSE(calls.empty());
    std::uint64_t previous = 0;
    for (const auto& [env, delta] : calls) {
      EXPECT_GT(env.version(), previous);
      EXPECT_TRUE(delta.removed.empty())
          << "version " << env.version() << " removed " << delta.removed.size();
      previous = env.version();
    }
  }

  echo.signal(SIGTERM);
  // To the end of its output (a line at most kPatience after the one before: a loaded machine may pause it).
  while (auto line = echo.read_line(kPatience)) check_line(*line);
  EXPECT_EQ(highest, last);
}

}  // namespace
}  // namespace cellmap::transport
