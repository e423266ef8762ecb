// SPDX-License-Identifier: Apache-2.0
// cellmapd on the simulated cell as a real process, a planner subscriber on loopback DDS, and `cellmap
// inject` as a separate process: injected changes arrive as exact deltas; versions survive SIGKILL without
// reuse (those run plain and with DDS Security on every participant). The daemon's status, SIGHUP, the
// latest-wins mailbox and a truncated state directory, read from its status topic and its log (plain).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <thread>

#include "cellmap/environment/version_store.hpp"
#include "cellmap/transport/scene_edits.hpp"
#include "daemon/service_e2e.hpp"
#include "support/dds_domains.hpp"

namespace cellmap {
namespace {

using namespace std::chrono_literals;
// Each test has its own domain (support/dds_domains.hpp) so ctest -j runs them side by side.
using test::kDaemonPatience;
using test::settled;

// The parameter: DDS Security on.
class CellmapdE2eTest : public ::testing::TestWithParam<bool> {
 protected:
  // This test's domain (plain or secured), with the service set up for it.
  int use_domain(int plain, int secure) {
    const int domain = GetParam() ? secure : plain;
    service_.emplace("e2e", GetParam() ? std::optional(domain) : std::nullopt);
    return domain;
  }
  [[nodiscard]] std::unique_ptr<test::ChildProcess> start_daemon(int domain) const {
    return service_->start_daemon(domain);
  }
  std::string inject(int domain, const std::vector<std::string>& args) const {
    return service_->inject(domain, args);
  }

  std::optional<test::ServiceFixture> service_;
};

INSTANTIATE_TEST_SUITE_P(, CellmapdE2eTest, ::testing::Bool(), test::security_name);

TEST_P(CellmapdE2eTest, InjectedBoxArrivesAsOneAddedBoxAndLeavesAsOneRemoved) {
  const int domain = use_domain(test::domain::kAddRemove, test::domain::kSecureAddRemove);
  auto daemon = start_daemon(domain);
  const dds::Participant participant = service_->participant(domain);
  test::DeltaRecorder recorder;
  transport::EnvironmentSubscriber planner(participant, "e2e", std::ref(recorder));
  transport::StatusReader status(participant, "e2e");
  ASSERT_TRUE(planner.wait_for_version(1, kDaemonPatience)) << "no first version from the daemon";
  const Environment before = settled(planner, status, "e2e", test::kLongQuietSweeps);
  ASSERT_FALSE(before.boxes().empty());

  // A box standing on a free part of the table (top at z = 0.75) between the fixture and the drum.
  const Eigen::Vector3d centre(2.12, 0.45, 0.9);
  const std::string name =
      inject(domain, {"add-box", "--center", "2.12,0.45,0.9", "--half-extents", "0.1,0.1,0.15"});
  ASSERT_FALSE(name.empty());
  ASSERT_TRUE(planner.wait_for_version(before.version() + 1, kDaemonPatience))
      << "the added box never arrived";
  const EnvironmentDelta added = recorder.to(before.version() + 1);
  ASSERT_EQ(added.added.size(), 1u);
  EXPECT_TRUE(added.modified.empty());
  EXPECT_TRUE(added.removed.empty());
  const Box box = added.added[0];
  EXPECT_TRUE(box.contains(centre)) << "the new box does not hold the injected obstacle";
  EXPECT_TRUE(box.contains(centre + Eigen::Vector3d(0.09, 0.09, 0.14)));
  const Environment with_box = settled(planner, status, "e2e", test::kLongQuietSweeps);
  for (const Box& old : before.boxes()) {
    const Box* same = with_box.find(old.id);
    ASSERT_NE(same, nullptr) << "box " << old.id << " vanished";
    EXPECT_TRUE(same_box(*same, old)) << "box " << old.id << " changed";
  }

  inject(domain, {"remove", "--name", name});
  ASSERT_TRUE(planner.wait_for_version(with_box.version() + 1, kDaemonPatience))
      << "the removal never arrived";
  const EnvironmentDelta removed = recorder.to(with_box.version() + 1);
  EXPECT_EQ(removed.removed, std::vector<std::uint64_t>{box.id});
  EXPECT_TRUE(removed.added.empty());

  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
}

TEST_P(CellmapdE2eTest, KilledDaemonResumesWithoutReusingVersionsAndLateJoinerGetsLatest) {
  const int domain = use_domain(test::domain::kRestart, test::domain::kSecureRestart);
  auto daemon = start_daemon(domain);
  std::optional<Environment> before_kill;
  {
    const dds::Participant participant = service_->participant(domain);
    transport::EnvironmentSubscriber planner(participant, "e2e");
    transport::StatusReader status(participant, "e2e");
    ASSERT_TRUE(planner.wait_for_version(1, kDaemonPatience));
    before_kill = settled(planner, status, "e2e", test::kLongQuietSweeps);
  }
  const std::uint64_t last = before_kill->version();
  // The default scene names a workspace over the table: its unseen space is published as unknown boxes,
  // which survive the kill with the obstacle boxes (compared box by box below).
  const auto unknown = [](const Environment& env) {
    return std::count_if(env.boxes().begin(), env.boxes().end(),
                         [](const Box& box) { return box.space == BoxSpace::kUnknown; });
  };
  ASSERT_GT(unknown(*before_kill), 0) << "no unknown boxes before the kill";
  daemon->signal(SIGKILL);
  daemon->wait();

  daemon = start_daemon(domain);
  // A late joiner gets the persisted environment at once, under the version it had, in one callback.
  const dds::Participant participant = service_->participant(domain);
  std::atomic<int> callbacks{0};
  transport::EnvironmentSubscriber late(participant, "e2e",
                                        [&](const Environment&, const EnvironmentDelta&) { ++callbacks; });
  ASSERT_TRUE(late.wait_for_version(last, kDaemonPatience));
  const Environment resumed = *late.environment();
  EXPECT_EQ(callbacks.load(), 1) << "the late joiner did not get the latest version in one callback";
  // The number `last` still means what subscribers saw before the kill (same stamp and boxes); a resumed
  // daemon that republished under a new number is above it, with the same boxes.
  if (resumed.version() == last) {
    EXPECT_TRUE(resumed == *before_kill) << "version " << last << " came back with other content";
  } else {
    EXPECT_GT(resumed.version(), last);
  }
  ASSERT_EQ(resumed.boxes().size(), before_kill->boxes().size());
  for (const Box& old : before_kill->boxes()) {
    const Box* same = resumed.find(old.id);
    ASSERT_NE(same, nullptr) << "box " << old.id << " vanished in the restart";
    EXPECT_TRUE(same_box(*same, old)) << "box " << old.id << " changed in the restart";
  }
  EXPECT_EQ(unknown(resumed), unknown(*before_kill));

  EXPECT_FALSE(
      inject(domain, {"add-box", "--center", "0.5,1.5,0.95", "--half-extents", "0.08,0.08,0.2"}).empty());
  // The resumed daemon goes on making versions: the injected box arrives in one above the resumed one.
  const Eigen::Vector3d injected(0.5, 1.5, 0.95);
  const auto holds_injected = [&] {
    const Environment env = *late.environment();
    return std::any_of(env.boxes().begin(), env.boxes().end(),
                       [&](const Box& box) { return box.contains(injected); });
  };
  const auto deadline = std::chrono::steady_clock::now() + kDaemonPatience;
  while (!holds_injected() && std::chrono::steady_clock::now() < deadline)
    late.wait_for_version(late.environment()->version() + 1, 1s);
  EXPECT_TRUE(holds_injected()) << "the box injected after the restart never arrived";
  EXPECT_GT(late.environment()->version(), resumed.version());
  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
}

// The number of the sweep a per-sweep log line ("2026-11-30T20:05:36.620 info sweep 12: 5 frames, ...") is
// about, or 0.
constexpr const char* kSweepLine = " info sweep ";
std::uint64_t sweep_number(const std::string& line) {
  const std::size_t at = line.find(kSweepLine);
  return at == std::string::npos ? 0
                                 : std::strtoull(line.c_str() + at + std::strlen(kSweepLine), nullptr, 10);
}

// The status of a simulated daemon after its first sweep, before any version.
void expect_first_sweep_status(const transport::CellStatus& status) {
  EXPECT_EQ(status.state, "running");
  EXPECT_EQ(status.sweeps, 1u);
  EXPECT_EQ(status.version, 0u);  // settling: no version yet
  EXPECT_EQ(status.boxes, 0u);
  ASSERT_FALSE(status.sensors.empty());
  for (const transport::SensorStatus& sensor : status.sensors)
    EXPECT_EQ(sensor.state, "streaming") << sensor.name;
  EXPECT_GT(status.last_sweep_ns, 0);
}

// A running daemon's status agrees with `env`, the version subscribers have.
void expect_status_of(const transport::CellStatus& status, const Environment& env) {
  EXPECT_EQ(status.state, "running");
  EXPECT_EQ(status.version, env.version());
  EXPECT_EQ(status.boxes, env.boxes().size());
  // The sweep that made the version ended just before it was stamped; later sweeps end later.
  EXPECT_GT(status.last_sweep_ns, env.stamp_ns() - 1'000'000'000);
}

// SIGHUP re-reads log_level and sweep_period and refuses a bad file; the status of the simulated daemon
// before and after its first version, and the final `stopped`. One daemon, plain DDS.
TEST(CellmapdStatusE2eTest, SighupReloadsLogLevelAndSweepPeriodAndStatusFollowsTheVersions) {
  test::ServiceFixture service("reload");
  const auto write_config = [&](const std::string& keys) {
    std::ofstream(service.config_file(), std::ios::trunc)
        << "cell: reload\nstatus_period: 0.2\nsource: {noise: false}\n"
        << keys;
  };
  write_config("sweep_period: 60\nlog_level: info\n");  // one sweep, then a minute's pause
  auto daemon = service.start_daemon(test::domain::kReload, /*log_on_stdout=*/true);
  test::DaemonLog log(*daemon);
  const dds::Participant participant = service.participant(test::domain::kReload);
  transport::StatusReader reader(participant);
  const auto status_where = [&](const std::function<bool(const transport::CellStatus&)>& accept,
                                std::chrono::milliseconds patience = kDaemonPatience) {
    return test::wait_for_status(reader, "reload", log, accept, patience);
  };

  ASSERT_TRUE(log.wait_for(std::string(kSweepLine) + "1: ")) << "no first sweep";
  const auto first = status_where([](const transport::CellStatus& s) { return s.sweeps >= 1; });
  ASSERT_TRUE(first.has_value()) << "no status of the simulated daemon";
  expect_first_sweep_status(*first);

  // sweep_period 60 → 0.2 at once (the next sweep would otherwise come a minute later), log_level → warn:
  // the per-sweep info lines stop.
  write_config("sweep_period: 0.2\nlog_level: warn\n");
  daemon->signal(SIGHUP);
  const auto flowing = status_where([](const transport::CellStatus& s) { return s.sweeps >= 6; }, 45s);
  ASSERT_TRUE(flowing.has_value()) << "sweep_period not reloaded: no sweeps after SIGHUP";

  // A bad file is refused with one error line naming the key; the daemon goes on as it was.
  write_config("sweep_period: -1\nlog_level: info\n");
  daemon->signal(SIGHUP);
  const std::optional<std::string> refused = log.wait_for("SIGHUP: config not reloaded");
  ASSERT_TRUE(refused.has_value()) << "a bad config on SIGHUP was not refused";
  EXPECT_NE(refused->find("sweep_period"), std::string::npos) << *refused;
  const std::uint64_t at_refusal = flowing->sweeps;
  ASSERT_TRUE(status_where([&](const transport::CellStatus& s) { return s.sweeps >= at_refusal + 3; }))
      << "sweeps stopped after a refused reload";
  EXPECT_EQ(log.count(kSweepLine), 1u) << "log_level warn was not applied, or not kept after the refusal";

  // Back to info: the reload is logged, and so are the sweeps again.
  write_config("sweep_period: 0.2\nlog_level: info\n");
  daemon->signal(SIGHUP);
  EXPECT_TRUE(log.wait_for("SIGHUP: reloaded log_level=info sweep_period=0.2 s").has_value());
  const std::optional<std::string> sweep_line = log.wait_for(kSweepLine);
  ASSERT_TRUE(sweep_line.has_value()) << "no sweep logged at info level";
  EXPECT_GT(sweep_number(*sweep_line), at_refusal);

  // The status agrees with the version subscribers have.
  transport::EnvironmentSubscriber planner(participant, "reload");
  ASSERT_TRUE(test::wait_for_version(planner, 1, log)) << "no first version";
  const Environment env = *planner.environment();
  const auto after_version =
      status_where([&](const transport::CellStatus& s) { return s.version == env.version(); });
  ASSERT_TRUE(after_version.has_value()) << "no status with version " << env.version();
  EXPECT_GT(env.boxes().size(), 0u);
  expect_status_of(*after_version, env);

  // SIGTERM: the last report says `stopped`, with the version it stopped at.
  daemon->signal(SIGTERM);
  const auto stopped = status_where([](const transport::CellStatus& s) { return s.state == "stopped"; });
  ASSERT_TRUE(stopped.has_value()) << "no final stopped status";
  EXPECT_EQ(stopped->version, planner.environment()->version());
  EXPECT_EQ(stopped->boxes, planner.environment()->boxes().size());
  EXPECT_TRUE(log.wait_for("stopped at version " + std::to_string(stopped->version)).has_value());
  EXPECT_EQ(test::exit_code(daemon->wait()), 0);
}

// The number right before the first `label` in `line` ("…: 5 frames, …" with " frames, " → 5); 0 if absent.
std::uint64_t number_before(const std::string& line, const std::string& label) {
  const std::size_t at = line.find(label);
  if (at == std::string::npos) return 0;
  std::size_t begin = at;
  while (begin > 0 && std::isdigit(static_cast<unsigned char>(line[begin - 1]))) --begin;
  return std::strtoull(line.substr(begin, at - begin).c_str(), nullptr, 10);
}

// sweep_period 0: the simulated cell sweeps as fast as the daemon fuses its frames, while the first version
// (settle_sweeps 0: the first sweep makes it) segments the whole cell at 1 cm, which takes seconds. With
// `sweep_backlog: 1` only the newest gathered sweep waits meanwhile: every sweep is processed or dropped
// whole, its frames counted in the status's dropped_frames and in the per-sweep log line. (Measured: 8
// sweeps rendered, 2 processed.)
TEST(CellmapdStatusE2eTest, SweepsArrivingFasterThanProcessedAreDroppedAndCounted) {
  constexpr std::uint64_t kSweeps = 8;
  test::ServiceFixture service("mailbox");
  std::ofstream(service.config_file(), std::ios::trunc)
      << "cell: mailbox\nsweep_period: 0\nsweep_backlog: 1\nstatus_period: 0.2\nsource: {noise: false}\n"
         "occupancy: {resolution: 0.01}\nchange: {settle_sweeps: 0}\n";
  auto daemon = service.start_daemon(test::domain::kMailbox, /*log_on_stdout=*/true, kSweeps);
  test::DaemonLog log(*daemon);
  const dds::Participant participant = service.participant(test::domain::kMailbox);
  transport::StatusReader reader(participant);
  const auto stopped = test::wait_for_status(
      reader, "mailbox", log, [](const transport::CellStatus& s) { return s.state == "stopped"; });
  ASSERT_TRUE(stopped.has_value()) << "no final stopped status";
  EXPECT_EQ(test::exit_code(daemon->wait()), 0);
  log.drain();
  // The last sweep's line counts every drop (the last sweep gathered is never replaced).
  std::string last_sweep;
  for (const std::string& line : log.lines())
    if (sweep_number(line) > 0) last_sweep = line;
  EXPECT_EQ(sweep_number(last_sweep), stopped->sweeps);
  const std::uint64_t frames_per_sweep = number_before(last_sweep, " frames, ");
  ASSERT_GT(frames_per_sweep, 1u) << last_sweep;
  const std::uint64_t dropped_sweeps = number_before(last_sweep, " sweeps dropped");
  EXPECT_GE(dropped_sweeps, 1u) << "no sweep was dropped: was anything queued? " << last_sweep;
  EXPECT_EQ(stopped->sweeps + dropped_sweeps, kSweeps);
  EXPECT_EQ(stopped->dropped_frames, dropped_sweeps * frames_per_sweep) << "whole sweeps are dropped";
  EXPECT_NE(last_sweep.find(", " + std::to_string(stopped->dropped_frames) + " frames dropped"),
            std::string::npos)
      << last_sweep;
}

// A change confirmed and waiting in the gather window (change.gather_sweeps) when the daemon is killed: the
// restarted daemon resumes from the last version, whose map predates the change, so it finds the change
// again and publishes it once: one version above the resumed one, one box holding it.
TEST(CellmapdStateE2eTest, AChangeWaitingToBeGatheredWhenKilledComesOutOnceAfterTheRestart) {
  test::ServiceFixture service("gather", "change: {settle_sweeps: 2, gather_sweeps: 10}\n");
  const int domain = test::domain::kGatherRestart;
  const Eigen::Vector3d centre(2.12, 0.45, 0.9);  // on a free part of the table, as above
  const std::vector<std::string> add_box{"add-box", "--center", "2.12,0.45,0.9", "--half-extents",
                                         "0.1,0.1,0.15"};
  {
    auto daemon = service.start_daemon(domain, /*log_on_stdout=*/true);
    test::DaemonLog log(*daemon);
    ASSERT_TRUE(log.wait_for("version 1: ").has_value()) << "no first version";
    EXPECT_FALSE(service.inject(domain, add_box).empty());
    // The sweep that confirms the box: its change now waits 10 sweeps (2 s) to be published.
    std::optional<std::string> confirmed;
    while ((confirmed = log.wait_for(" change regions")) &&
           confirmed->find(" 0 change regions") != std::string::npos) {
    }
    ASSERT_TRUE(confirmed.has_value()) << "the injected box was never confirmed";
    daemon->signal(SIGKILL);
    daemon->wait();
    log.drain();
    ASSERT_EQ(log.count("version 2: "), 0u) << "the change went out before the kill: " << *confirmed;
  }

  auto daemon = service.start_daemon(domain);
  const dds::Participant participant = service.participant(domain);
  transport::EnvironmentSubscriber planner(participant, "gather");
  transport::StatusReader status(participant, "gather");
  ASSERT_TRUE(planner.wait_for_version(1, kDaemonPatience)) << "the restarted daemon announced nothing";
  const std::uint64_t resumed = planner.environment()->version();
  EXPECT_FALSE(service.inject(domain, add_box).empty());  // the simulated cell starts from its scene again
  ASSERT_TRUE(test::wait_until_boxed(planner, centre)) << "the waiting change never came out";
  const Environment after = settled(planner, status, "gather");
  const auto holds_box = [&](const Box& box) { return box.contains(centre); };
  EXPECT_EQ(std::count_if(after.boxes().begin(), after.boxes().end(), holds_box), 1);
  EXPECT_EQ(after.version(), resumed + 1) << "the change came out in more than one version";
  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
}

// cellmapd started on a state directory whose newest snapshot JSON is truncated: it resumes from the previous
// good version under a higher number (subscribers may have seen the lost one), renames the bad file and
// logs one line about it.
TEST(CellmapdStateE2eTest, TruncatedNewestSnapshotResumesFromThePreviousGoodVersion) {
  test::ServiceFixture service("resume");
  std::ofstream(service.config_file(), std::ios::trunc)
      << "cell: resume\nsweep_period: 60\nstatus_period: 0.2\nsource: {noise: false}\n";  // one sweep
  Box kept;
  kept.id = 1;
  kept.center = {1.0, 1.0, 1.0};
  kept.half_extents = {0.1, 0.2, 0.3};
  Box lost = kept;
  lost.id = 2;
  lost.center = {2.0, 1.0, 1.0};
  std::filesystem::path newest;
  {
    VersionStore store(service.state_dir(), "resume");
    store.save(Environment("resume", 1, 1'000'000'000, {kept}));
    store.save(Environment("resume", 2, 2'000'000'000, {kept, lost}));
    for (const auto& entry : std::filesystem::directory_iterator(service.state_dir())) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("environment-", 0) == 0 && entry.path().extension() == ".json" && entry.path() > newest)
        newest = entry.path();
    }
  }
  ASSERT_FALSE(newest.empty());
  std::filesystem::resize_file(newest, std::filesystem::file_size(newest) / 2);

  auto daemon = service.start_daemon(test::domain::kResume, /*log_on_stdout=*/true);
  test::DaemonLog log(*daemon);
  const dds::Participant participant = service.participant(test::domain::kResume);
  transport::EnvironmentSubscriber late(participant, "resume");
  ASSERT_TRUE(test::wait_for_version(late, 3, log)) << "did not resume above the lost version 2";
  const Environment resumed = *late.environment();
  EXPECT_EQ(resumed.version(), 3u);
  ASSERT_EQ(resumed.boxes().size(), 1u);
  EXPECT_TRUE(same_box(resumed.boxes()[0], kept));
  EXPECT_FALSE(std::filesystem::exists(newest));
  EXPECT_TRUE(std::filesystem::exists(newest.string() + ".corrupt"));
  ASSERT_TRUE(log.wait_for("resumed version 3").has_value());
  EXPECT_EQ(log.count(newest.filename().string()), 1u) << "the truncated file is not reported in one line";
  daemon->signal(SIGTERM);
  EXPECT_EQ(test::exit_code(daemon->wait()), 0);
}

}  // namespace
}  // namespace cellmap
