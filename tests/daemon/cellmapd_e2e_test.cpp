// cellmapd on the simulated cell as a real process, a planner subscriber on loopback DDS, and `cellmap
// inject` as a separate process: injected changes arrive as exact deltas; versions survive SIGKILL without
// reuse. Each test runs plain and with DDS Security on every participant.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <thread>

#include "daemon/service_e2e.hpp"

namespace cellmap {
namespace {

using namespace std::chrono_literals;
// Transport tests use 110-149; each test here has its own domain so ctest -j runs them side by side; the
// secured variants use 190-191.
constexpr int kAddRemoveDomain = 150;
constexpr int kRestartDomain = 151;
constexpr int kSecureAddRemoveDomain = 190;
constexpr int kSecureRestartDomain = 191;
using test::kPatience;
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
  const int domain = use_domain(kAddRemoveDomain, kSecureAddRemoveDomain);
  auto daemon = start_daemon(domain);
  const dds::Participant participant = service_->participant(domain);
  test::DeltaRecorder recorder;
  transport::EnvironmentSubscriber planner(participant, "e2e", std::ref(recorder));
  ASSERT_TRUE(planner.wait_for_version(1, kPatience)) << "no first version from the daemon";
  const Environment before = settled(planner, 5s);
  ASSERT_FALSE(before.boxes().empty());

  // A box standing on a free part of the table (top at z = 0.75) between the fixture and the drum.
  const Eigen::Vector3d centre(2.12, 0.45, 0.9);
  const std::string name =
      inject(domain, {"add-box", "--center", "2.12,0.45,0.9", "--half-extents", "0.1,0.1,0.15"});
  ASSERT_FALSE(name.empty());
  ASSERT_TRUE(planner.wait_for_version(before.version() + 1, kPatience)) << "the added box never arrived";
  const EnvironmentDelta added = recorder.last();
  ASSERT_EQ(added.added.size(), 1u);
  EXPECT_TRUE(added.modified.empty());
  EXPECT_TRUE(added.removed.empty());
  const Box box = added.added[0];
  EXPECT_TRUE(box.contains(centre)) << "the new box does not hold the injected obstacle";
  EXPECT_TRUE(box.contains(centre + Eigen::Vector3d(0.09, 0.09, 0.14)));
  const Environment with_box = settled(planner, 5s);
  for (const Box& old : before.boxes()) {
    const Box* same = with_box.find(old.id);
    ASSERT_NE(same, nullptr) << "box " << old.id << " vanished";
    EXPECT_TRUE(same_box(*same, old)) << "box " << old.id << " changed";
  }

  inject(domain, {"remove", "--name", name});
  ASSERT_TRUE(planner.wait_for_version(with_box.version() + 1, kPatience)) << "the removal never arrived";
  const EnvironmentDelta removed = recorder.last();
  EXPECT_EQ(removed.removed, std::vector<std::uint64_t>{box.id});
  EXPECT_TRUE(removed.added.empty());

  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
}

TEST_P(CellmapdE2eTest, KilledDaemonResumesWithoutReusingVersionsAndLateJoinerGetsLatest) {
  const int domain = use_domain(kRestartDomain, kSecureRestartDomain);
  auto daemon = start_daemon(domain);
  std::optional<Environment> before_kill;
  {
    const dds::Participant participant = service_->participant(domain);
    transport::EnvironmentSubscriber planner(participant, "e2e");
    ASSERT_TRUE(planner.wait_for_version(1, kPatience));
    before_kill = settled(planner, 5s);
  }
  const std::uint64_t last = before_kill->version();
  daemon->signal(SIGKILL);
  daemon->wait();

  daemon = start_daemon(domain);
  // A late joiner gets the persisted environment at once, under the version it had.
  const dds::Participant participant = service_->participant(domain);
  transport::EnvironmentSubscriber late(participant, "e2e");
  ASSERT_TRUE(late.wait_for_version(last, kPatience));
  const Environment resumed = *late.environment();
  // The number `last` still means what subscribers saw before the kill (same stamp and boxes); a resumed
  // daemon that republished under a new number is above it.
  if (resumed.version() == last) {
    EXPECT_TRUE(resumed == *before_kill) << "version " << last << " came back with other content";
  }
  EXPECT_EQ(resumed.boxes().size(), before_kill->boxes().size());

  EXPECT_FALSE(
      inject(domain, {"add-box", "--center", "0.5,1.5,0.95", "--half-extents", "0.08,0.08,0.2"}).empty());
  // The resumed daemon goes on making versions: the injected box arrives in one above the resumed one.
  const Eigen::Vector3d injected(0.5, 1.5, 0.95);
  const auto holds_injected = [&] {
    const Environment env = *late.environment();
    return std::any_of(env.boxes().begin(), env.boxes().end(),
                       [&](const Box& box) { return box.contains(injected); });
  };
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (!holds_injected() && std::chrono::steady_clock::now() < deadline)
    late.wait_for_version(late.environment()->version() + 1, 1s);
  EXPECT_TRUE(holds_injected()) << "the box injected after the restart never arrived";
  EXPECT_GT(late.environment()->version(), resumed.version());
  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
}

}  // namespace
}  // namespace cellmap
