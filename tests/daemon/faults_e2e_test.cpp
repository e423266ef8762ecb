// SPDX-License-Identifier: Apache-2.0
// cellmapd as a real process with its state directory on a small tmpfs (tests run as root; without the
// right to mount they skip): the disk full when the first version is due and when a later one is, the state
// directory read-only and removed. Each time the status says degraded with the reason, subscribers (a late
// joiner too) keep the last version that went out, and the held version goes out once the disk works again,
// without a restart. With DDS Security on: the full disk at the first version, and a refused DDS write of
// the version keeper (a publication that throws, as a failing write does) with a tool's `cellmap echo`
// receiving in a process of its own.
#include <gtest/gtest.h>
#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cellmap/environment/version_store.hpp"
#include "cellmap/transport/environment_publisher.hpp"
#include "daemon/service_e2e.hpp"
#include "support/dds_domains.hpp"
#include "versions.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
// The first version's map state is about 0.5 MB: room for three versions and a filler.
constexpr const char* kTmpfsOptions = "size=4m";
// A short settling (exact depths fill the map in a few sweeps): the tests are about what follows.
constexpr const char* kShortSettling = "change: {settle_sweeps: 3}\n";

// A tmpfs mounted for the test's lifetime, with the state directory inside it.
class SmallDisk {
 public:
  SmallDisk() {
    if (::mount("tmpfs", dir_.path().c_str(), "tmpfs", 0, kTmpfsOptions) != 0) {
      error_ = std::string("cannot mount a tmpfs (needs root): ") + std::strerror(errno);
      return;
    }
    fs::create_directories(state_dir());
  }
  ~SmallDisk() {
    if (error_.empty()) ::umount2(dir_.path().c_str(), MNT_DETACH);
  }
  SmallDisk(const SmallDisk&) = delete;
  SmallDisk& operator=(const SmallDisk&) = delete;

  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] fs::path state_dir() const { return dir_.path() / "state"; }

  // Takes every free byte with a file beside the state directory.
  void fill() const {
    std::ofstream filler(filler_path(), std::ios::binary | std::ios::trunc);
    const std::string chunk(64 * 1024, 'x');
    while (filler.write(chunk.data(), static_cast<std::streamsize>(chunk.size()))) {
    }
  }
  void free() const { fs::remove(filler_path()); }

  void make_read_only(bool read_only) const {
    const unsigned long flags = MS_REMOUNT | (read_only ? MS_RDONLY : 0);
    ASSERT_EQ(::mount("tmpfs", dir_.path().c_str(), "tmpfs", flags, kTmpfsOptions), 0)
        << std::strerror(errno);
  }

 private:
  [[nodiscard]] fs::path filler_path() const { return dir_.path() / "filler"; }

  test::TempDir dir_{"cellmap-small-disk"};
  std::string error_;
};

std::function<bool(const transport::CellStatus&)> degraded_by(const std::string& cause) {
  return [cause](const transport::CellStatus& s) {
    return s.state == "degraded" && s.reason.find(cause) != std::string::npos;
  };
}

bool running(const transport::CellStatus& s) {
  return s.state == "running" && s.reason.empty();
}

class FaultsE2eTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::use_loopback(); }
  void SetUp() override {
    if (!disk_.error().empty()) GTEST_SKIP() << disk_.error();
  }

  SmallDisk disk_;
};

TEST_F(FaultsE2eTest, FullDiskHoldsTheFirstVersionUntilSpaceComesBackThenReadOnlyHoldsTheNext) {
  const test::ServiceFixture service("full-first", kShortSettling, disk_.state_dir());
  const dds::Participant participant(test::domain::kFirstVersionFault);
  transport::StatusReader reader(participant);
  transport::EnvironmentSubscriber planner(participant, service.cell());
  disk_.fill();
  auto daemon = service.start_daemon(test::domain::kFirstVersionFault);

  const auto full = test::wait_for_status(reader, service.cell(), degraded_by("No space left on device"));
  ASSERT_TRUE(full.has_value()) << "no degraded status while the disk is full";
  EXPECT_EQ(full->reason.rfind("version 1 not saved: ", 0), 0u) << full->reason;
  EXPECT_EQ(full->version, 0u);
  EXPECT_FALSE(planner.environment().has_value()) << "a version went out unsaved";

  disk_.free();
  ASSERT_TRUE(planner.wait_for_version(1, test::kDaemonPatience)) << "the held version never went out";
  EXPECT_FALSE(planner.environment()->boxes().empty());
  ASSERT_TRUE(test::wait_for_status(reader, service.cell(), running).has_value()) << "never running again";
  const Environment before = test::settled(planner, reader, service.cell());

  // Read-only: the version with the injected box is held until the directory can be written again.
  disk_.make_read_only(true);
  const Eigen::Vector3d centre(2.12, 0.45, 0.9);
  ASSERT_FALSE(service
                   .inject(test::domain::kFirstVersionFault,
                           {"add-box", "--center", "2.12,0.45,0.9", "--half-extents", "0.1,0.1,0.15"})
                   .empty());
  const auto read_only = test::wait_for_status(reader, service.cell(), degraded_by("Read-only file system"));
  ASSERT_TRUE(read_only.has_value()) << "no degraded status while the state directory is read-only";
  EXPECT_EQ(read_only->version, before.version());
  EXPECT_EQ(planner.environment()->version(), before.version());

  disk_.make_read_only(false);
  ASSERT_TRUE(planner.wait_for_version(before.version() + 1, test::kDaemonPatience))
      << "nothing went out after rw";
  EXPECT_TRUE(test::wait_until_boxed(planner, centre)) << "the box injected while read-only never arrived";
  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
}

TEST_F(FaultsE2eTest, FullDiskHoldsALaterVersionAndARemovedDirectoryIsWrittenAgain) {
  const test::ServiceFixture service("full-later", kShortSettling, disk_.state_dir());
  const dds::Participant participant(test::domain::kLaterVersionFault);
  transport::StatusReader reader(participant);
  transport::EnvironmentSubscriber planner(participant, service.cell());
  auto daemon = service.start_daemon(test::domain::kLaterVersionFault);
  ASSERT_TRUE(planner.wait_for_version(1, test::kDaemonPatience)) << "no first version";
  const Environment before = test::settled(planner, reader, service.cell());

  disk_.fill();
  const Eigen::Vector3d centre(0.5, 1.5, 0.95);
  ASSERT_FALSE(service
                   .inject(test::domain::kLaterVersionFault,
                           {"add-box", "--center", "0.5,1.5,0.95", "--half-extents", "0.08,0.08,0.2"})
                   .empty());
  const auto full = test::wait_for_status(reader, service.cell(), degraded_by("No space left on device"));
  ASSERT_TRUE(full.has_value()) << "no degraded status while the disk is full";
  EXPECT_EQ(full->version, before.version());
  {
    // A planner that joins now gets the last version that went out.
    transport::EnvironmentSubscriber late(participant, service.cell());
    ASSERT_TRUE(late.wait_for_version(before.version(), test::kDaemonPatience));
    EXPECT_TRUE(*late.environment() == before);
  }

  disk_.free();
  ASSERT_TRUE(test::wait_until_boxed(planner, centre))
      << "the box injected while the disk was full never arrived";
  const Environment with_box = test::settled(planner, reader, service.cell());

  // The state directory removed under the running daemon: its boxes are saved again as the next version.
  fs::remove_all(disk_.state_dir());
  ASSERT_TRUE(planner.wait_for_version(with_box.version() + 1, test::kDaemonPatience)) << "not saved again";
  const Environment again = *planner.environment();
  EXPECT_TRUE(diff(with_box, again).empty()) << "the boxes changed";
  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
  EXPECT_EQ(VersionStore(disk_.state_dir(), service.cell()).recovered().environment.version(),
            again.version());
}

TEST_F(FaultsE2eTest, SecuredFullDiskHoldsTheFirstVersionUntilSpaceComesBack) {
  const int domain = test::domain::kSecureFirstVersionFault;
  const test::ServiceFixture service("full-secure", kShortSettling, disk_.state_dir(), domain);
  const dds::Participant participant = service.participant(domain);
  transport::StatusReader reader(participant, service.cell());
  transport::EnvironmentSubscriber planner(participant, service.cell());
  disk_.fill();
  auto daemon = service.start_daemon(domain);
  const auto full = test::wait_for_status(reader, service.cell(), degraded_by("No space left on device"));
  ASSERT_TRUE(full.has_value()) << "no degraded status while the disk is full";
  EXPECT_EQ(full->version, 0u);
  EXPECT_FALSE(planner.environment().has_value()) << "a version went out unsaved";
  disk_.free();
  ASSERT_TRUE(planner.wait_for_version(1, test::kDaemonPatience)) << "the held version never went out";
  EXPECT_FALSE(planner.environment()->boxes().empty());
  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
}

TEST(SecuredVersionKeeperTest, RefusedDdsWriteIsRetriedUntilItGoesOut) {
  const int domain = test::domain::kSecureRefusedWrite;
  const std::string cell = "write-secure";
  test::use_secure_loopback();
  const test::TestCredentials credentials(cell, domain);
  const dds::Participant participant(static_cast<std::uint32_t>(domain),
                                     credentials.as(security::Role::kDaemon));
  transport::EnvironmentPublisher publisher(participant, cell);
  std::vector<std::string> argv{CELLMAP_TOOL, "echo", "--domain",  std::to_string(domain),
                                "--count",    "4",    "--timeout", "90"};
  const std::vector<std::string> flags = credentials.flags(security::Role::kTool);
  argv.insert(argv.end(), flags.begin(), flags.end());
  test::ChildProcess echo(argv);
  ASSERT_TRUE(publisher.wait_for_subscribers(1, test::kDaemonPatience)) << "the tool's echo never matched";
  ASSERT_TRUE(publisher.wait_for_snapshot_readers(1, test::kDaemonPatience))
      << "the tool's echo never matched the snapshots";

  bool refuse = false;
  const test::TempDir dir;
  VersionStore store(dir.path() / "state", cell);
  daemon::VersionKeeper keeper(store, [&](const Environment& env, const EnvironmentDelta& delta) {
    if (refuse) throw Error("dds write: refused");
    publisher.publish(env, delta);
  });
  Box box;
  box.half_extents = Eigen::Vector3d::Constant(0.1);
  std::vector<Box> boxes;
  const auto holding = [&](std::uint64_t boxes_held) {
    for (std::uint64_t id = boxes.size() + 1; id <= boxes_held; ++id) {
      box.id = id;
      box.center = Eigen::Vector3d(0.3 * static_cast<double>(id), 0.5, 0.5);
      boxes.push_back(box);
    }
    return CellPipeline(CellPipelineConfig{}, boxes, 10);
  };
  keeper.flush(holding(2));
  refuse = true;
  keeper.flush(holding(3));
  EXPECT_EQ(keeper.fault(), "version 2 not published: dds write: refused");
  EXPECT_TRUE(keeper.pending());
  refuse = false;
  keeper.flush(holding(3));
  EXPECT_FALSE(keeper.pending());
  EXPECT_EQ(keeper.fault(), "");

  // Version 1 (a delta from 0 and the snapshot), then version 2 (its delta from 1 and the snapshot).
  std::vector<nlohmann::json> got;
  while (const std::optional<std::string> line = echo.read_line(test::kDaemonPatience)) {
    got.push_back(nlohmann::json::parse(*line));
  }
  EXPECT_EQ(echo.wait(), 0);
  ASSERT_EQ(got.size(), 4u);
  EXPECT_EQ(got[2]["from_version"], 1);
  EXPECT_EQ(got[2]["to_version"], 2);
  EXPECT_EQ(got[3]["version"], 2);
  EXPECT_EQ(got[3]["boxes"].size(), 3u);
}

}  // namespace
}  // namespace cellmap
