// SPDX-License-Identifier: Apache-2.0
// The example planner (examples/planner) as a real process against cellmapd on the simulated cell: a box
// injected into its path arrives as a delta adding exactly that box and the planner reports the path blocked
// by it; removing the box frees the path again; a clean daemon restart does not read as "all removed". Plain
// and with DDS Security on every process and participant. Unknown boxes (published by the test itself, with
// known answers) block the path as "unknown region" unless the planner is told to ignore unknown space; an
// object no sensor sees blocks it as unknown space until the sensors see it and its own box blocks it.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/transport/environment_publisher.hpp"
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
  // The planner's default path runs 0.15 m above the table at x = 2.12 from y = 0.45 to 0.8, clear of the
  // unknown space at the table's front edge.
  std::vector<std::string> planner_argv = service.planner(domain);
  planner_argv.push_back("--json");
  test::ChildProcess planner(planner_argv);

  ASSERT_TRUE(observer.wait_for_version(1, test::kDaemonPatience)) << "no first version from the daemon";
  const nlohmann::json first = next_state(planner);
  EXPECT_EQ(first.value("state", ""), "free") << first.dump();
  const Environment before = test::settled(observer, status, "planner", test::kLongQuietSweeps);

  const std::string name =
      service.inject(domain, {"add-box", "--center", "2.12,0.65,0.9", "--half-extents", "0.1,0.1,0.15"});
  ASSERT_FALSE(name.empty());
  ASSERT_TRUE(observer.wait_for_version(before.version() + 1, test::kDaemonPatience))
      << "the box never arrived";
  const EnvironmentDelta added = recorder.to(before.version() + 1);
  ASSERT_EQ(added.added.size(), 1u);
  EXPECT_TRUE(added.modified.empty());
  EXPECT_TRUE(added.removed.empty());
  const Box box = added.added[0];
  EXPECT_TRUE(box.contains(Eigen::Vector3d(2.12, 0.65, 0.9)));

  const nlohmann::json blocked = next_state(planner);
  EXPECT_EQ(blocked.value("state", ""), "blocked") << blocked.dump();
  EXPECT_EQ(blocked.value("box", std::uint64_t{0}), box.id) << blocked.dump();
  EXPECT_EQ(blocked.value("version", std::uint64_t{0}), added.to_version) << blocked.dump();
  EXPECT_EQ(blocked.value("added", 0), 1) << blocked.dump();
  // The path first comes within the margin (0.02) of the box's side at y = 0.65 − 0.1 − 0.05 − margin.
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
      service.inject(domain, {"add-box", "--center", "2.12,0.65,0.9", "--half-extents", "0.1,0.1,0.15"});
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

Box cube(std::uint64_t id, const Eigen::Vector3d& center, double half, BoxSpace space) {
  Box box;
  box.id = id;
  box.center = center;
  box.half_extents = Eigen::Vector3d::Constant(half);
  box.space = space;
  return box;
}

// The test publishes the environments itself, so every distance is a known answer. The planner's path runs
// straight from y = 0.1 to 0.8 at x 2.12, z 1.0, checkpoint k (of 50) at y = 0.1 + 0.7 k / 49, carrying
// a cube of half 0.05 with a margin of 0.02: it is blocked from the first checkpoint whose cube comes within
// 0.02 of a box's face at y = f, 0.1 + 0.7 k / 49 + 0.05 > f − 0.02.
TEST(PlannerUnknownSpaceTest, UnknownRegionBlocksThePathUnlessIgnored) {
  test::use_loopback();
  const int domain = test::domain::kPlannerUnknown;
  const std::string cell = "planner-unknown";
  const dds::Participant daemon(static_cast<std::uint32_t>(domain));
  transport::EnvironmentPublisher publisher(daemon, cell);
  // Version 1: an unknown box across the path (face at y = 0.35: checkpoint 13, y 0.286, 0.014 m short of
  // it) and an obstacle off the path.
  const Box unknown = cube(5, Eigen::Vector3d(2.12, 0.45, 1.0), 0.1, BoxSpace::kUnknown);
  const Box aside = cube(3, Eigen::Vector3d(0.5, 1.5, 0.85), 0.1, BoxSpace::kOccupied);
  const Environment first(cell, 1, 1'000, {aside, unknown});
  publisher.publish(first);

  // `cellmap echo` shows the unknown box's space; the obstacle's line stays as it was (no "space").
  test::ChildProcess echo({CELLMAP_TOOL, "echo", "--domain", std::to_string(domain), "--cell", cell,
                           "--count", "1", "--timeout", "60"});
  const nlohmann::json echoed = nlohmann::json::parse(echo.read_line(test::kDaemonPatience).value_or("{}"));
  EXPECT_EQ(echo.wait(), 0);
  const nlohmann::json& boxes = echoed.contains("boxes") ? echoed["boxes"] : echoed["added"];
  ASSERT_EQ(boxes.size(), 2u) << echoed.dump();
  EXPECT_EQ(boxes[0].value("id", 0), 3) << echoed.dump();
  EXPECT_FALSE(boxes[0].contains("space")) << echoed.dump();
  EXPECT_EQ(boxes[1].value("id", 0), 5) << echoed.dump();
  EXPECT_EQ(boxes[1].value("space", ""), "unknown") << echoed.dump();

  const std::vector<std::string> planner_argv{CELLMAP_PLANNER,
                                              "--domain",
                                              std::to_string(domain),
                                              "--cell",
                                              cell,
                                              "--control-points",
                                              "2.12,0.1,1.0;2.12,0.45,1.0;2.12,0.8,1.0"};
  test::ChildProcess careful(planner_argv);
  std::vector<std::string> ignoring_argv = planner_argv;
  ignoring_argv.insert(ignoring_argv.end(), {"--ignore-unknown", "--json"});
  test::ChildProcess ignoring(ignoring_argv);

  EXPECT_EQ(
      careful.read_line(test::kDaemonPatience).value_or(""),
      "version 1 (+2 ~0 -0): path blocked by unknown region 5 at checkpoint 13 (t 0.265, x 2.120 y 0.286 "
      "z 1.000), distance 0.014 m");
  EXPECT_EQ(next_state(ignoring).value("state", ""), "free");

  // Version 2: an obstacle on the path behind the unknown box (face at y = 0.6: checkpoint 31, y 0.543,
  // 0.007 m short of it). The unknown box still blocks first, so the careful planner prints nothing new.
  const Box behind = cube(8, Eigen::Vector3d(2.12, 0.65, 1.0), 0.05, BoxSpace::kOccupied);
  const Environment second(cell, 2, 2'000, {aside, unknown, behind});
  publisher.publish(second, diff(first, second));
  const nlohmann::json blocked = next_state(ignoring);
  EXPECT_EQ(blocked.value("state", ""), "blocked") << blocked.dump();
  EXPECT_EQ(blocked.value("version", 0), 2) << blocked.dump();
  EXPECT_EQ(blocked.value("box", 0), 8) << blocked.dump();
  EXPECT_EQ(blocked.value("space", ""), "occupied") << blocked.dump();
  EXPECT_EQ(blocked.value("checkpoint", 0), 31) << blocked.dump();
  EXPECT_NEAR(blocked.value("distance", 1.0), 0.6 - (0.1 + 0.7 * 31 / 49 + 0.05), 1e-9) << blocked.dump();

  // Version 3: the unknown box goes (the sensors looked there): now the obstacle blocks the careful planner.
  const Environment third(cell, 3, 3'000, {aside, behind});
  publisher.publish(third, diff(second, third));
  EXPECT_EQ(
      careful.read_line(test::kDaemonPatience).value_or(""),
      "version 3 (+0 ~0 -1): path blocked by box 8 at checkpoint 31 (t 0.633, x 2.120 y 0.543 z 1.000), "
      "distance 0.007 m");

  for (test::ChildProcess* planner : {&careful, &ignoring}) {
    planner->signal(SIGTERM);
    EXPECT_EQ(planner->wait(), 0);
  }
}

// The default cell with a shelf over pallet b, 0.33 m above it, and under the shelf, where the Kinect looking
// down from the gantry never sees, a 16 cm cube (tests/unknown/unknown_cell_test.cpp has the geometry).
std::string scene_with_a_hidden_cube() {
  std::string scene = read_file(std::string(CELLMAP_SOURCE_DIR) + "/config/cell.yaml");
  const std::string list = "\nobstacles:\n";
  const std::size_t at = scene.find(list);
  EXPECT_NE(at, std::string::npos) << "config/cell.yaml has no obstacles list";
  scene.insert(at + list.size(),
               "  - {name: shelf, box: {half_extents: [0.35, 0.3, 0.02]}, center: [2.2, 1.4, 1.25]}\n"
               "  - {name: hidden, box: {half_extents: [0.08, 0.08, 0.08]}, center: [2.2, 1.4, 0.974]}\n");
  return scene;
}

// cellmapd on the noisy default cell with an object no sensor sees; the example planner's path runs under the
// shelf through the object. The path is blocked by unknown space from the first version on and never free;
// once the shelf is taken away the object's box blocks it, and the unknown box there went in that version.
TEST(PlannerUnknownSpaceTest, AnObjectNoSensorSeesBlocksThePathAsUnknownUntilItsOwnBoxDoes) {
  const int domain = test::domain::kPlannerHidden;
  const test::ServiceFixture service("planner-hidden");
  const std::filesystem::path scene = service.config_file().parent_path() / "scene.yaml";
  write_file_atomically(scene, scene_with_a_hidden_cube());
  std::ofstream(service.config_file()) << "cell: planner-hidden\nsweep_period: 0.2\nstatus_period: 0.5\n"
                                       << "source: {scene: " << scene.string() << "}\n";
  auto daemon = service.start_daemon(domain);
  const dds::Participant participant = service.participant(domain);
  transport::EnvironmentSubscriber observer(participant, service.cell());
  std::vector<std::string> planner_argv = service.planner(domain);
  planner_argv.insert(planner_argv.end(),
                      {"--json", "--control-points", "1.95,1.4,1.1;2.2,1.4,1.1;2.45,1.4,1.1"});
  test::ChildProcess planner(planner_argv);

  const nlohmann::json first = next_state(planner);
  EXPECT_EQ(first.value("state", ""), "blocked") << first.dump();
  EXPECT_EQ(first.value("space", ""), "unknown") << first.dump();
  ASSERT_TRUE(observer.wait_for_version(first.value("version", std::uint64_t{1}), test::kDaemonPatience));
  const Eigen::Vector3d hidden(2.2, 1.4, 0.974);
  const auto holding = [&](BoxSpace space) {
    const std::optional<Environment> env = observer.environment();
    return std::count_if(env->boxes().begin(), env->boxes().end(),
                         [&](const Box& box) { return box.space == space && box.contains(hidden); });
  };
  EXPECT_EQ(holding(BoxSpace::kOccupied), 0) << "the hidden cube has an obstacle box";
  EXPECT_GT(holding(BoxSpace::kUnknown), 0) << "the hidden cube's place is not unknown";

  service.inject(domain, {"remove", "--name", "shelf"});
  nlohmann::json state = first;
  while (state.value("space", "") != "occupied" || state.value("box", std::uint64_t{0}) == 0) {
    state = next_state(planner);
    ASSERT_EQ(state.value("state", ""), "blocked") << "the path was free: " << state.dump();
  }
  ASSERT_TRUE(observer.wait_for_version(state.value("version", std::uint64_t{0}), test::kDaemonPatience));
  EXPECT_EQ(holding(BoxSpace::kOccupied), 1) << "no obstacle box holds the cube";
  EXPECT_EQ(holding(BoxSpace::kUnknown), 0) << "the cube's place is still unknown";
  std::cout << "hidden cube: version " << first.value("version", 0) << " blocked by unknown region "
            << first.value("box", 0) << ", version " << state.value("version", 0) << " by box "
            << state.value("box", 0) << "\n";
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
