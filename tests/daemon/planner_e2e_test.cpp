// SPDX-License-Identifier: Apache-2.0
// The example planner (examples/planner) as a real process against cellmapd on the simulated cell: a box
// injected into its path arrives as a delta adding exactly that box and the planner reports the path blocked
// by it; removing the box frees the path again; a clean daemon restart does not read as "all removed". Plain
// and with DDS Security on every process and participant.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "daemon/service_e2e.hpp"
#include "support/dds_domains.hpp"

namespace cellmap {
namespace {

using namespace std::chrono_literals;

// The next JSON line the planner prints, or a failure.
nlohmann::json next_state(test::ChildProcess& planner) {
  const std::optional<std::string> line = planner.read_line(test::kDaemonPatience);
  if (!line) {
    ADD_FAILURE() << "the planner printed nothing";
    return nlohmann::json::object();
  }
  return nlohmann::json::parse(*line);
}

// The parameter: DDS Security on.
class PlannerE2eTest : public ::testing::TestWithParam<bool> {};
INSTANTIATE_TEST_SUITE_P(, PlannerE2eTest, ::testing::Bool(), test::security_name);

TEST_P(PlannerE2eTest, InjectedBoxBlocksThePathAndItsRemovalFreesIt) {
  const int domain = GetParam() ? test::domain::kSecurePlanner : test::domain::kPlanner;
  const test::ServiceFixture service("planner", GetParam() ? std::optional(domain) : std::nullopt);
  auto daemon = service.start_daemon(domain);
  const dds::Participant participant = service.participant(domain);
  test::DeltaRecorder recorder;
  transport::EnvironmentSubscriber observer(participant, "planner", std::ref(recorder));
  transport::StatusReader status(participant,
                                 service.cell());  // tells when the stopped daemon's writers are gone
  // The planner's default path runs 0.25 m above the table at x = 2.12 from y = 0.1 to 0.8.
  std::vector<std::string> planner_argv = service.planner(domain);
  planner_argv.push_back("--json");
  test::ChildProcess planner(planner_argv);

  ASSERT_TRUE(observer.wait_for_version(1, test::kDaemonPatience)) << "no first version from the daemon";
  const nlohmann::json first = next_state(planner);
  EXPECT_EQ(first.value("state", ""), "free") << first.dump();
  const Environment before = test::settled(observer, status, "planner", test::kLongQuietSweeps);

  const std::string name =
      service.inject(domain, {"add-box", "--center", "2.12,0.45,0.9", "--half-extents", "0.1,0.1,0.15"});
  ASSERT_FALSE(name.empty());
  ASSERT_TRUE(observer.wait_for_version(before.version() + 1, test::kDaemonPatience))
      << "the box never arrived";
  const EnvironmentDelta added = recorder.to(before.version() + 1);
  ASSERT_EQ(added.added.size(), 1u);
  EXPECT_TRUE(added.modified.empty());
  EXPECT_TRUE(added.removed.empty());
  const Box box = added.added[0];
  EXPECT_TRUE(box.contains(Eigen::Vector3d(2.12, 0.45, 0.9)));

  const nlohmann::json blocked = next_state(planner);
  EXPECT_EQ(blocked.value("state", ""), "blocked") << blocked.dump();
  EXPECT_EQ(blocked.value("box", std::uint64_t{0}), box.id) << blocked.dump();
  EXPECT_EQ(blocked.value("version", std::uint64_t{0}), added.to_version) << blocked.dump();
  EXPECT_EQ(blocked.value("added", 0), 1) << blocked.dump();
  // The path first comes within the margin (0.02) of the box's side at y = 0.45 − 0.1 − 0.05 − margin.
  ASSERT_TRUE(blocked.contains("position"));
  EXPECT_NEAR(blocked["position"][0].get<double>(), 2.12, 1e-9);
  EXPECT_GT(blocked["position"][1].get<double>(), box.center.y() - box.half_extents.y() - 0.1);
  EXPECT_LT(blocked["position"][1].get<double>(), box.center.y());
  EXPECT_LT(blocked.value("distance", 1.0), 0.02);

  const Environment with_box = test::settled(observer, status, "planner");
  service.inject(domain, {"remove", "--name", name});
  ASSERT_TRUE(observer.wait_for_version(with_box.version() + 1, test::kDaemonPatience))
      << "removal never arrived";
  EXPECT_EQ(recorder.to(with_box.version() + 1).removed, std::vector<std::uint64_t>{box.id});
  const nlohmann::json free = next_state(planner);
  EXPECT_EQ(free.value("state", ""), "free") << free.dump();
  EXPECT_EQ(free.value("removed", 0), 1) << free.dump();

  // A clean stop and restart of the daemon (its writers deleted) must not look like "all boxes removed":
  // the local copy keeps every box, and the restarted daemon goes on above the last version.
  const Environment last = test::settled(observer, status, "planner");
  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
  // The daemon's writers have left this participant (its status writer is seen leaving with them).
  const auto deadline = std::chrono::steady_clock::now() + test::kDaemonPatience;
  bool departed = false;
  while (!departed && std::chrono::steady_clock::now() < deadline) {
    (void)status.take(100ms);
    departed =
        std::find(status.departed().begin(), status.departed().end(), "planner") != status.departed().end();
  }
  ASSERT_TRUE(departed) << "the stopped daemon never left";
  EXPECT_EQ(*observer.environment(), last);
  daemon = service.start_daemon(domain);
  const std::string again =
      service.inject(domain, {"add-box", "--center", "2.12,0.45,0.9", "--half-extents", "0.1,0.1,0.15"});
  ASSERT_TRUE(observer.wait_for_version(last.version() + 1, test::kDaemonPatience))
      << "nothing after the restart";
  const nlohmann::json blocked_again = next_state(planner);
  EXPECT_EQ(blocked_again.value("state", ""), "blocked") << blocked_again.dump();
  EXPECT_EQ(blocked_again.value("removed", -1), 0) << blocked_again.dump();
  EXPECT_GT(blocked_again.value("box", std::uint64_t{0}), box.id) << "a box id was reused";
  EXPECT_EQ(observer.environment()->boxes().size(), last.boxes().size() + 1);

  planner.signal(SIGTERM);
  EXPECT_EQ(planner.wait(), 0);
  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
}

TEST(PlannerCommandLineTest, BadPathIsRefusedWithOneLine) {
  // stderr through the pipe: the reason is the only output.
  test::ChildProcess planner(
      {"/bin/sh", "-c", "exec \"$0\" \"$@\" 2>&1", CELLMAP_PLANNER, "--control-points", "1,2;3,4,5"});
  EXPECT_EQ(planner.read_line(test::kDaemonPatience).value_or(""),
            "cellmap_example_planner: --control-points: '1,2' is not x,y,z");
  EXPECT_EQ(planner.read_line(test::kDaemonPatience), std::nullopt);  // the end of its output
  const int status = planner.wait();
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
}

}  // namespace
}  // namespace cellmap
