// SPDX-License-Identifier: Apache-2.0
#include "cellmap/environment/version_store.hpp"

#include <gtest/gtest.h>

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include "support/test_support.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;

// A rotation that reads back bit for bit: box_set_from_json re-normalises quaternions, so use one that
// normalisation leaves unchanged.
Eigen::Quaterniond stable_rotation(double yaw) {
  Eigen::Quaterniond q(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  while (!(q.normalized().coeffs() == q.coeffs())) q.normalize();
  return q;
}

// The content of version v: known from v alone, so a reload can be checked field by field.
Environment content(std::uint64_t version) {
  std::vector<Box> boxes;
  for (std::uint64_t id = 1; id <= 1 + version % 7; ++id) {
    Box box;
    box.id = id;
    box.center = {0.1 * id, 0.001 * version, 1.0 / 3.0};
    box.half_extents = {0.05, 0.1, 0.2};
    box.rotation = stable_rotation(0.01 * version);
    box.points = version * 10 + id;
    boxes.push_back(box);
  }
  return Environment("cell-a", version, static_cast<std::int64_t>(version) * 1'000'000'000, boxes);
}

// The file name of the box-id marker `next-box-id-<n>`.
std::string marker_name(std::uint64_t n) {
  char name[48];
  std::snprintf(name, sizeof name, "next-box-id-%020llu", static_cast<unsigned long long>(n));
  return name;
}

std::string blob_of(std::uint64_t version) {
  return "octree-" + std::to_string(version) + std::string(1000, 'x');
}

TEST(VersionStoreTest, FreshDirectoryStartsAtVersionOne) {
  test::TempDir dir;
  VersionStore store(dir.path() / "state", "cell-a");
  EXPECT_EQ(store.recovered().environment, Environment("cell-a"));
  EXPECT_FALSE(store.recovered().blob.has_value());
  EXPECT_TRUE(store.recovered().problems.empty());
  EXPECT_EQ(store.next_version(), 1u);
}

TEST(VersionStoreTest, TheStateDirectoryIsItsOwnersOnly) {
  test::TempDir dir;
  namespace fs = std::filesystem;
  (void)VersionStore(dir.path() / "new", "cell-a");
  EXPECT_EQ(fs::status(dir.path() / "new").permissions(), fs::perms::owner_all);
  fs::create_directory(dir.path() / "old");
  fs::permissions(dir.path() / "old", fs::perms::all);  // as a umask of 000 leaves it
  (void)VersionStore(dir.path() / "old", "cell-a");
  EXPECT_EQ(fs::status(dir.path() / "old").permissions(), fs::perms::owner_all);
}

TEST(VersionStoreTest, RoundTripKeepsEveryFieldAndTheBlob) {
  test::TempDir dir;
  {
    VersionStore store(dir.path(), "cell-a");
    for (std::uint64_t v = 1; v <= 5; ++v) store.save(content(v), blob_of(v));
    EXPECT_EQ(store.next_version(), 6u);
  }
  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().environment, content(5));
  ASSERT_TRUE(store.recovered().blob.has_value());
  EXPECT_EQ(read_file(*store.recovered().blob), blob_of(5));
  EXPECT_TRUE(store.recovered().problems.empty());
  EXPECT_EQ(store.next_version(), 6u);
  // Only the current and the previous good version stay on disk; the snapshot is a boxes file.
  EXPECT_FALSE(fs::exists(dir.path() / "environment-00000000000000000003.json"));
  EXPECT_TRUE(fs::exists(dir.path() / "environment-00000000000000000004.json"));
  EXPECT_EQ(read_box_file(dir.path() / "environment-00000000000000000005.json").boxes.size(),
            content(5).boxes().size());
}

// A version saved with its boxes first and its blob attached after (as cellmapd publishes between the two):
// before the attach it reads back without a blob, after it with the blob; attaching is for the newest
// version without one only.
TEST(VersionStoreTest, ABlobAttachedAfterTheBoxesReadsBackWithThem) {
  test::TempDir dir;
  {
    VersionStore store(dir.path(), "cell-a");
    store.save(content(1), blob_of(1));
    store.save(content(2));
    {
      const VersionStore crashed_here(dir.path(), "cell-a");
      EXPECT_EQ(crashed_here.recovered().environment, content(2));
      EXPECT_FALSE(crashed_here.recovered().blob.has_value()) << "the boxes load, the map is lost";
      EXPECT_TRUE(crashed_here.recovered().problems.empty());
    }
    EXPECT_THROW(store.attach_blob(1, blob_of(1)), Error) << "not the newest version";
    store.attach_blob(2, blob_of(2));
    EXPECT_THROW(store.attach_blob(2, blob_of(2)), Error) << "it has one now";
    store.save(content(3), blob_of(3));
    EXPECT_THROW(store.attach_blob(3, blob_of(3)), Error) << "saved with one";
  }
  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().environment, content(3));
  ASSERT_TRUE(store.recovered().blob.has_value());
  EXPECT_EQ(read_file(*store.recovered().blob), blob_of(3));
  // Version 2, the previous good one, kept the blob attached to it.
  fs::remove(dir.path() / "environment-00000000000000000003.json");
  const VersionStore previous(dir.path(), "cell-a");
  EXPECT_EQ(previous.recovered().environment, content(2));
  ASSERT_TRUE(previous.recovered().blob.has_value());
  EXPECT_EQ(read_file(*previous.recovered().blob), blob_of(2));
}

TEST(VersionStoreTest, RefusesBackwardsAndForeignCells) {
  test::TempDir dir;
  VersionStore store(dir.path(), "cell-a");
  store.save(content(3));
  EXPECT_THROW(store.save(content(3)), Error);
  EXPECT_THROW(store.save(content(2)), Error);
  EXPECT_THROW(store.save(Environment("cell-b", 9, 0, {})), Error);
  EXPECT_THROW(VersionStore(dir.path(), "cell-b"), Error);
}

TEST(VersionStoreTest, CorruptNewestFallsBackToPreviousGoodAndSaysSo) {
  test::TempDir dir;
  {
    VersionStore store(dir.path(), "cell-a");
    for (std::uint64_t v = 1; v <= 3; ++v) store.save(content(v), blob_of(v));
  }
  const fs::path newest = dir.path() / "environment-00000000000000000003.json";
  const std::string text = read_file(newest);
  std::ofstream(newest, std::ios::trunc) << text.substr(0, text.size() / 2);  // truncated mid-document

  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().environment, content(2));
  EXPECT_EQ(read_file(*store.recovered().blob), blob_of(2));
  ASSERT_EQ(store.recovered().problems.size(), 1u);
  EXPECT_NE(store.recovered().problems[0].find("environment-00000000000000000003.json"), std::string::npos)
      << store.recovered().problems[0];
  EXPECT_TRUE(fs::exists(newest.string() + ".corrupt"));  // kept for inspection, not dropped
  EXPECT_EQ(store.next_version(), 4u);                    // 3 may have been published: never reused
}

TEST(VersionStoreTest, DamagedBlobFallsBackToo) {
  test::TempDir dir;
  {
    VersionStore store(dir.path(), "cell-a");
    for (std::uint64_t v = 1; v <= 2; ++v) store.save(content(v), blob_of(v));
  }
  std::ofstream(dir.path() / "environment-00000000000000000002.blob", std::ios::trunc)
      << blob_of(2).substr(0, 10);
  {
    VersionStore store(dir.path(), "cell-a");
    EXPECT_EQ(store.recovered().environment, content(1));
    ASSERT_EQ(store.recovered().problems.size(), 1u);
    EXPECT_NE(store.recovered().problems[0].find("truncated"), std::string::npos);
    store.save(content(3));
  }
  // A later open finds 3 (no blob) and 1 as the previous good; the corrupt 2 stays aside.
  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().environment, content(3));
  EXPECT_FALSE(store.recovered().blob.has_value());
  EXPECT_TRUE(store.recovered().problems.empty());
  EXPECT_EQ(store.next_version(), 4u);
}

TEST(VersionStoreTest, EveryCorruptSnapshotMeansEmptyButVersionsGoOn) {
  test::TempDir dir;
  {
    VersionStore store(dir.path(), "cell-a");
    store.save(content(1));
    store.save(content(2));
  }
  std::ofstream(dir.path() / "environment-00000000000000000001.json", std::ios::trunc) << "{";
  std::ofstream(dir.path() / "environment-00000000000000000002.json", std::ios::trunc) << "";
  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().environment.version(), 0u);
  EXPECT_EQ(store.recovered().problems.size(), 2u);
  EXPECT_EQ(store.next_version(), 3u);
}

// Found by fuzzing (fuzz_version_store): a number beyond a double made the JSON parser throw an exception the
// store did not catch, so the daemon would have died at start instead of skipping the snapshot.
TEST(VersionStoreTest, FuzzFindingsAreSkippedAsCorrupt) {
  test::TempDir dir;
  fs::copy_file(test::fuzz_regression("version_store", "number_overflow.json"),
                dir.path() / "environment-00000000000000000007.json");
  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().environment.version(), 0u);
  ASSERT_EQ(store.recovered().problems.size(), 1u);
  const std::string& problem = store.recovered().problems[0];
  EXPECT_NE(problem.find("environment-00000000000000000007.json: not valid JSON ("), std::string::npos)
      << problem;
  EXPECT_NE(problem.find("number overflow"), std::string::npos) << problem;
  EXPECT_EQ(problem.find('\n'), std::string::npos) << problem;
  EXPECT_EQ(store.next_version(), 8u);
}

TEST(VersionStoreTest, ForeignAndOutOfRangeNamesAreLeftAlone) {
  test::TempDir dir;
  std::ofstream(dir.path() / "environment-99999999999999999999.json") << "{}";
  std::ofstream(dir.path() / "notes.txt") << "operator notes";
  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.next_version(), 1u);
  EXPECT_TRUE(fs::exists(dir.path() / "notes.txt"));
}

// Runs in a forked child until killed: each loop publishes one version, in the order the store documents
// (saved, then published). The "publication" is the version number written to `fd`.
[[noreturn]] void write_versions_forever(const fs::path& dir, int fd) {
  VersionStore store(dir, "cell-a");
  for (;;) {
    const std::uint64_t v = store.next_version();
    store.save(content(v), blob_of(v), v + 10);
    if (::write(fd, &v, sizeof v) != sizeof v) ::_exit(3);
  }
}

TEST(VersionStoreTest, KillDuringWritesNeverReusesAVersion) {
  test::TempDir dir;
  std::mt19937 random(12);
  std::uniform_int_distribution<int> delay_us(0, 40'000);
  std::uint64_t published = 0;
  std::uint64_t loaded_before = 0;
  for (int round = 0; round < 25; ++round) {
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(fds[0]);
      try {
        write_versions_forever(dir.path(), fds[1]);
      } catch (...) {
        ::_exit(2);
      }
    }
    ::close(fds[1]);
    // Let the child get a few versions out (it must have started writing), then kill it at a random instant.
    std::uint64_t v = 0;
    ASSERT_EQ(::read(fds[0], &v, sizeof v), static_cast<ssize_t>(sizeof v));
    published = std::max(published, v);
    ::usleep(static_cast<useconds_t>(delay_us(random)));
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "child failed on its own, exit " << WEXITSTATUS(status);
    while (::read(fds[0], &v, sizeof v) == static_cast<ssize_t>(sizeof v)) published = std::max(published, v);
    ::close(fds[0]);

    VersionStore store(dir.path(), "cell-a");
    const Environment& env = store.recovered().environment;
    EXPECT_TRUE(store.recovered().problems.empty()) << store.recovered().problems.front();
    ASSERT_NE(env.version(), 0u) << "round " << round;
    EXPECT_EQ(env, content(env.version())) << "round " << round;
    ASSERT_TRUE(store.recovered().blob.has_value());
    EXPECT_EQ(read_file(*store.recovered().blob), blob_of(env.version()));
    EXPECT_GE(env.version(), loaded_before);
    // Saved before published: nothing published is lost.
    EXPECT_GE(env.version(), published) << "round " << round;
    EXPECT_GT(store.next_version(), published)
        << "round " << round << ": a published version would be reused";
    // Every id a saved version handed out (its counter, v + 10) stays handed out.
    EXPECT_GE(store.recovered().next_box_id, published + 10) << "round " << round;
    loaded_before = env.version();
  }
  EXPECT_GE(published, 25u);  // every round published at least once
}

Box box_with_id(std::uint64_t id) {
  Box box;
  box.id = id;
  box.center = {0.5 * static_cast<double>(id), 0.0, 0.5};
  box.half_extents = {0.1, 0.1, 0.1};
  return box;
}

// Versions 1-3 of a cell whose box 4 appeared in version 2 and went again in 3; the counter is at 5.
void save_removed_box_history(VersionStore& store) {
  store.save(Environment("cell-a", 1, 1, {box_with_id(1), box_with_id(2), box_with_id(3)}), blob_of(1), 4);
  store.save(Environment("cell-a", 2, 2, {box_with_id(1), box_with_id(2), box_with_id(3), box_with_id(4)}),
             blob_of(2), 5);
  store.save(Environment("cell-a", 3, 3, {box_with_id(1), box_with_id(2), box_with_id(3)}), blob_of(3), 5);
}

TEST(VersionStoreTest, BoxIdCounterIsKeptWithTheVersionsAndNeverGoesBack) {
  test::TempDir dir;
  {
    VersionStore store(dir.path(), "cell-a");
    EXPECT_EQ(store.next_box_id(), 1u);
    save_removed_box_history(store);
    EXPECT_EQ(store.next_box_id(), 5u);
    store.save(Environment("cell-a", 4, 4, {box_with_id(1)}));  // no counter given: it stays where it was
    EXPECT_EQ(store.next_box_id(), 5u);
    store.save(Environment("cell-a", 5, 5, {box_with_id(1), box_with_id(7)}), std::nullopt, 2);
    EXPECT_EQ(store.next_box_id(), 8u);  // never below the ids of the version itself
  }
  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().next_box_id, 8u);
  EXPECT_EQ(store.next_box_id(), 8u);
  EXPECT_TRUE(store.recovered().problems.empty());
}

// The marker reserves ids ahead: versions that hand out ids within the reserve write no new marker, the
// one that passes it writes one (and removes the old), and a clean reopen takes the counter, not the marker.
TEST(VersionStoreTest, MarkerIsRaisedOnlyWhenTheIdsPassItsReserve) {
  test::TempDir dir;
  const auto markers = [&] {
    std::vector<std::string> names;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir.path())) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("next-box-id-", 0) == 0) names.push_back(name);
    }
    return names;
  };
  const std::uint64_t reserve = VersionStore::kBoxIdsReserved;
  {
    VersionStore store(dir.path(), "cell-a");
    store.save(Environment("cell-a", 1, 1, {box_with_id(1)}), std::nullopt, 2);
    EXPECT_EQ(markers(), std::vector<std::string>{marker_name(2 + reserve)});
    for (std::uint64_t v = 2; v <= 5; ++v) {
      store.save(Environment("cell-a", v, v, {box_with_id(v)}), std::nullopt, v + 1);
      EXPECT_EQ(markers(), std::vector<std::string>{marker_name(2 + reserve)}) << v;
    }
    store.save(Environment("cell-a", 6, 6, {box_with_id(1)}), std::nullopt, 3 + reserve);
    EXPECT_EQ(markers(), std::vector<std::string>{marker_name(3 + 2 * reserve)});
  }
  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().next_box_id, 3 + reserve);
}

// Version 4 added box 5 and is lost (its blob or its JSON): the store falls back to version 3, whose boxes
// end at id 3 and whose own counter says 5. Both ids 4 (removed in 3) and 5 (added in 4) may have been
// published, and the counter is above them.
TEST(VersionStoreTest, LostNewestVersionDoesNotBringBackItsBoxIds) {
  for (const char* lost :
       {"environment-00000000000000000004.blob", "environment-00000000000000000004.json"}) {
    test::TempDir dir;
    {
      VersionStore store(dir.path(), "cell-a");
      save_removed_box_history(store);
      store.save(
          Environment("cell-a", 4, 4, {box_with_id(1), box_with_id(2), box_with_id(3), box_with_id(5)}),
          blob_of(4), 6);
    }
    std::ofstream(dir.path() / lost, std::ios::trunc) << "garbage";
    VersionStore store(dir.path(), "cell-a");
    EXPECT_EQ(store.recovered().environment.version(), 3u) << lost;
    // From the marker, which reserved ids ahead of the counter of version 1.
    EXPECT_EQ(store.recovered().next_box_id, 4u + VersionStore::kBoxIdsReserved)
        << lost << ": an id handed out before would come again";
    EXPECT_EQ(store.next_version(), 5u) << lost;
  }
}

TEST(VersionStoreTest, SnapshotsOfAnOlderVersionWithoutTheCounterStillOpen) {
  test::TempDir dir;
  {
    VersionStore store(dir.path(), "cell-a");
    store.save(content(3), blob_of(3), 40);
  }
  // What an older cellmapd wrote: no next_box_id in the snapshot, no marker.
  const fs::path snapshot = dir.path() / "environment-00000000000000000003.json";
  nlohmann::json doc = nlohmann::json::parse(read_file(snapshot));
  doc.erase("next_box_id");
  std::ofstream(snapshot, std::ios::trunc) << doc.dump(1);
  fs::remove(dir.path() / marker_name(40 + VersionStore::kBoxIdsReserved));

  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().environment, content(3));
  EXPECT_EQ(read_file(*store.recovered().blob), blob_of(3));
  EXPECT_EQ(store.recovered().next_box_id, content(3).boxes().back().id + 1);  // above the ids it holds
  ASSERT_EQ(store.recovered().problems.size(), 1u);
  EXPECT_NE(store.recovered().problems[0].find("no next_box_id"), std::string::npos)
      << store.recovered().problems[0];
}

TEST(VersionStoreTest, ResumeSavesTheRecoveredBoxesAgainAboveALostNumber) {
  test::TempDir dir;
  {
    VersionStore fresh(dir.path(), "cell-a");
    EXPECT_EQ(fresh.resume(99), Environment("cell-a"));  // nothing to announce
    fresh.save(content(1), blob_of(1));
    fresh.save(content(2), blob_of(2));
  }
  {
    VersionStore store(dir.path(), "cell-a");
    EXPECT_EQ(store.resume(99), content(2));  // nothing lost: announced as it was
    EXPECT_EQ(store.next_version(), 3u);
  }
  std::ofstream(dir.path() / "environment-00000000000000000002.json", std::ios::trunc) << "{";
  {
    // 2 may have been published: version 1's boxes go out again as 3, stamped now, with the given blob.
    VersionStore store(dir.path(), "cell-a");
    const Environment resumed = store.resume(99, "map");
    EXPECT_EQ(resumed, Environment("cell-a", 3, 99, content(1).boxes()));
    EXPECT_EQ(store.next_version(), 4u);
  }
  VersionStore store(dir.path(), "cell-a");
  EXPECT_EQ(store.recovered().environment, Environment("cell-a", 3, 99, content(1).boxes()));
  EXPECT_EQ(read_file(*store.recovered().blob), "map");
}

TEST(VersionStoreTest, RemovedDirectoryIsNoticedAndRecreatedByTheNextSave) {
  test::TempDir dir;
  const fs::path state = dir.path() / "state";
  {
    VersionStore store(state, "cell-a");
    EXPECT_TRUE(store.holds_last_saved());  // nothing saved yet: nothing to lose
    store.save(content(1), blob_of(1), 20);
    EXPECT_TRUE(store.holds_last_saved());
    fs::remove_all(state);
    EXPECT_FALSE(store.holds_last_saved());
    store.save(content(2), blob_of(2));
    EXPECT_TRUE(store.holds_last_saved());
  }
  VersionStore store(state, "cell-a");
  EXPECT_EQ(store.recovered().environment, content(2));
  EXPECT_EQ(store.recovered().next_box_id, 20u);
  EXPECT_TRUE(fs::exists(state / marker_name(20 + VersionStore::kBoxIdsReserved)));
}

}  // namespace
}  // namespace cellmap
