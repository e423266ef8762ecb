// SPDX-License-Identifier: Apache-2.0
// cellmapd's versions: the pipeline recovered from a state directory, and each version saved before it is
// published to a real subscriber on loopback DDS, retried through save and write faults, stamped in order
// when the clock steps back.
#include "versions.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/transport/environment_publisher.hpp"
#include "cellmap/transport/environment_subscriber.hpp"
#include "support/dds_domains.hpp"
#include "support/test_support.hpp"
#include "transport/loopback.hpp"

namespace cellmap::daemon {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using test::kPatience;

Box box_with_id(std::uint64_t id) {
  Box box;
  box.id = id;
  box.center = {0.3 * static_cast<double>(id), 0.5, 0.5};
  box.half_extents = {0.1, 0.1, 0.1};
  return box;
}

std::vector<Box> boxes_with_ids(std::initializer_list<std::uint64_t> ids) {
  std::vector<Box> boxes;
  for (const std::uint64_t id : ids) boxes.push_back(box_with_id(id));
  return boxes;
}

std::vector<std::uint64_t> ids_of(const std::vector<Box>& boxes) {
  std::vector<std::uint64_t> ids;
  for (const Box& box : boxes) ids.push_back(box.id);
  return ids;
}

// One sweep of a 0.4 m wall 1 m in front of a sensor at the origin: something for a map state to hold.
Sweep wall_sweep() {
  Scan scan;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j)
      scan.points_C.push_back(pcl::PointXYZ(1.0f, 0.02f * i - 0.2f, 0.02f * j - 0.2f));
  }
  Sweep sweep;
  sweep.scans.push_back(std::move(scan));
  return sweep;
}

// A pipeline holding `ids` (an empty map: what is kept and published here is the boxes and the counter).
CellPipeline holding(std::initializer_list<std::uint64_t> ids, std::uint64_t next_box_id = 10) {
  return CellPipeline(CellPipelineConfig{}, boxes_with_ids(ids), next_box_id);
}

// A real publisher and subscriber for a cell named after the test (ctest runs the tests of this domain side
// by side); publications fail while `refuse` is set, as a refused DDS write does, and each checks that its
// version was on disk before it went out.
class KeeperTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::use_loopback(); }

  VersionKeeper::Publish publish() {
    return [this](const Environment& env, const EnvironmentDelta& delta) {
      if (refuse) throw Error("dds write: refused");
      EXPECT_TRUE(fs::exists(snapshot(env.version()))) << "version " << env.version() << " published unsaved";
      ++published_;
      publisher_.publish(env, delta);
    };
  }

  [[nodiscard]] fs::path snapshot(std::uint64_t version) const {
    char name[64];
    std::snprintf(name, sizeof name, "environment-%020llu.json", static_cast<unsigned long long>(version));
    return state_dir() / name;
  }
  [[nodiscard]] fs::path state_dir() const { return dir_.path() / "state"; }
  // The ids of the boxes the subscriber holds once it reached `version`.
  [[nodiscard]] std::vector<std::uint64_t> received(std::uint64_t version) const {
    EXPECT_TRUE(subscriber_.wait_for_version(version, kPatience))
        << "version " << version << " never arrived";
    return subscriber_.environment() ? ids_of(subscriber_.environment()->boxes())
                                     : std::vector<std::uint64_t>{};
  }

  bool refuse = false;
  int published_ = 0;  // versions the keeper published
  const std::string cell_ = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  test::TempDir dir_;
  dds::Participant participant_{test::domain::kKeeper};
  transport::EnvironmentPublisher publisher_{participant_, cell_};
  transport::EnvironmentSubscriber subscriber_{participant_, cell_};
};

TEST_F(KeeperTest, SavesEachVersionBeforePublishingAndRetriesARefusedWrite) {
  VersionStore store(state_dir(), cell_);
  VersionKeeper keeper(store, publish());
  keeper.flush(holding({}));  // nothing yet: no version
  EXPECT_EQ(keeper.published().version(), 0u);
  EXPECT_FALSE(keeper.pending());

  keeper.flush(holding({1, 2}));
  EXPECT_EQ(received(1), (std::vector<std::uint64_t>{1, 2}));
  keeper.flush(holding({1, 2}));  // unchanged: no version
  EXPECT_EQ(store.next_version(), 2u);

  // The DDS write fails: version 2 is saved, subscribers keep 1, and each flush tries again.
  refuse = true;
  keeper.flush(holding({1, 2, 3}));
  EXPECT_EQ(keeper.published().version(), 1u);
  EXPECT_TRUE(keeper.pending());
  EXPECT_EQ(keeper.fault(), "version 2 not published: dds write: refused");
  keeper.flush(holding({1, 2, 3, 4}));  // the boxes changed meanwhile: version 3, still refused
  EXPECT_EQ(keeper.fault(), "version 3 not published: dds write: refused");
  EXPECT_EQ(subscriber_.environment()->version(), 1u);

  refuse = false;
  keeper.flush(holding({1, 2, 3, 4}));
  EXPECT_EQ(received(3), (std::vector<std::uint64_t>{1, 2, 3, 4}));
  EXPECT_EQ(keeper.published().version(), 3u);
  EXPECT_FALSE(keeper.pending());
  EXPECT_EQ(keeper.fault(), "");
}

// A version goes out once its boxes are on disk; its map state follows: a restart before that finds the
// boxes without a map, one after finds both. A map state that cannot be saved is retried, the version out.
TEST_F(KeeperTest, PublishesOnceTheBoxesAreSavedAndSavesTheMapStateAfter) {
  VersionStore store(state_dir(), cell_);
  VersionKeeper keeper(store, publish());
  CellPipeline pipeline = holding({1, 2});
  (void)pipeline.process(wall_sweep());
  keeper.publish_boxes(pipeline);
  EXPECT_EQ(received(1), (std::vector<std::uint64_t>{1, 2}));
  EXPECT_TRUE(keeper.pending()) << "the map state is still owed";
  EXPECT_FALSE(VersionStore(state_dir(), cell_).recovered().blob.has_value());
  keeper.save_map_state(pipeline);
  EXPECT_FALSE(keeper.pending());
  const VersionStore reopened(state_dir(), cell_);
  ASSERT_TRUE(reopened.recovered().blob.has_value());
  EXPECT_EQ(read_file(*reopened.recovered().blob), pipeline.map_state());

  // Version 2's map state cannot be written (a directory stands where its file goes): it waits.
  CellPipeline changed = holding({1, 2, 3});
  keeper.publish_boxes(changed);
  EXPECT_EQ(received(2), (std::vector<std::uint64_t>{1, 2, 3}));
  fs::path blob = snapshot(2);
  blob.replace_extension(".blob");
  fs::create_directory(blob);
  keeper.save_map_state(changed);
  EXPECT_TRUE(keeper.pending());
  EXPECT_EQ(keeper.fault().rfind("map state of version 2 not saved: ", 0), 0u) << keeper.fault();
  fs::remove(blob);
  keeper.flush(changed);
  EXPECT_FALSE(keeper.pending());
  EXPECT_EQ(keeper.fault(), "");
  EXPECT_EQ(published_, 2) << "a map state saved late publishes nothing";
  EXPECT_TRUE(VersionStore(state_dir(), cell_).recovered().blob.has_value());
}

TEST_F(KeeperTest, UnusableStateDirectoryIsRetriedUntilItWorksAgain) {
  VersionStore store(state_dir(), cell_);
  VersionKeeper keeper(store, publish());
  keeper.flush(holding({1}));
  ASSERT_EQ(received(1), (std::vector<std::uint64_t>{1}));

  // The state directory is replaced by a file: nothing can be saved, so nothing new is published.
  fs::remove_all(state_dir());
  std::ofstream(state_dir()) << "in the way";
  keeper.flush(holding({1, 2}));
  EXPECT_TRUE(keeper.pending());
  EXPECT_EQ(keeper.fault().rfind("version 2 not saved: ", 0), 0u) << keeper.fault();
  keeper.flush(holding({1, 2}));
  EXPECT_EQ(keeper.published().version(), 1u);
  EXPECT_EQ(subscriber_.environment()->version(), 1u);

  fs::remove(state_dir());
  keeper.flush(holding({1, 2}));
  EXPECT_EQ(received(2), (std::vector<std::uint64_t>{1, 2}));
  EXPECT_EQ(keeper.fault(), "");
  EXPECT_FALSE(keeper.pending());
  EXPECT_TRUE(fs::exists(snapshot(2)));
}

TEST_F(KeeperTest, RemovedStateDirectoryIsSavedAgainAtOnce) {
  {
    VersionStore store(state_dir(), cell_);
    VersionKeeper keeper(store, publish());
    keeper.flush(holding({1, 2}, 7));
    ASSERT_EQ(received(1), (std::vector<std::uint64_t>{1, 2}));
    fs::remove_all(state_dir());
    keeper.flush(holding({1, 2}, 7));  // nothing changed in the cell, but a restart would find nothing
    EXPECT_EQ(received(2), (std::vector<std::uint64_t>{1, 2}));
  }
  VersionStore reopened(state_dir(), cell_);
  EXPECT_EQ(reopened.recovered().environment.version(), 2u);
  EXPECT_EQ(reopened.recovered().next_box_id, 7u);
}

TEST_F(KeeperTest, ClockSteppedBackStillGivesRisingStamps) {
  std::int64_t now = 5'000'000'000;
  VersionStore store(state_dir(), cell_);
  VersionKeeper keeper(store, publish(), [&now] { return now; });
  keeper.flush(holding({1}));
  EXPECT_EQ(keeper.published().stamp_ns(), 5'000'000'000);
  now = 1'000'000'000;  // an NTP step back by 4 s
  keeper.flush(holding({1, 2}));
  EXPECT_EQ(keeper.published().version(), 2u);
  EXPECT_EQ(keeper.published().stamp_ns(), 5'000'000'001);
  now = 9'000'000'000;
  keeper.flush(holding({1, 2, 3}));
  EXPECT_EQ(keeper.published().stamp_ns(), 9'000'000'000);
  EXPECT_EQ(received(3).size(), 3u);
}

TEST_F(KeeperTest, ResumeAnnouncesTheRecoveredVersionOrItsBoxesAboveALostNumber) {
  {
    VersionStore store(state_dir(), cell_);
    store.save(Environment(cell_, 1, 1, boxes_with_ids({1})));
    store.save(Environment(cell_, 2, 2, boxes_with_ids({1, 2})));
  }
  std::ofstream(snapshot(2), std::ios::trunc) << "{";  // version 2 may have been published, then lost
  VersionStore store(state_dir(), cell_);
  VersionKeeper keeper(store, publish());
  keeper.resume(recover_pipeline(CellPipelineConfig{}, store.recovered()));
  EXPECT_EQ(received(3), (std::vector<std::uint64_t>{1}));
  EXPECT_EQ(keeper.published().version(), 3u);
  EXPECT_FALSE(keeper.pending());
}

// Box 3 was added in version 2 and removed in version 3; version 3's map state is unreadable or missing.
// The map starts empty and the next new box must not get id 3 again.
TEST(RecoverPipelineTest, LostMapStateKeepsBoxIdsAboveEveryIdHandedOut) {
  const std::string garbage = "not a map state";
  for (const std::optional<std::string_view> blob :
       {std::optional<std::string_view>(garbage), std::optional<std::string_view>()}) {
    test::TempDir dir;
    {
      VersionStore store(dir.path(), "cell");
      store.save(Environment("cell", 1, 1, boxes_with_ids({1, 2})), "x", 3);
      store.save(Environment("cell", 2, 2, boxes_with_ids({1, 2, 3})), "x", 4);
      store.save(Environment("cell", 3, 3, boxes_with_ids({1, 2})), blob, 4);
    }
    const VersionStore store(dir.path(), "cell");
    const CellPipeline pipeline = recover_pipeline(CellPipelineConfig{}, store.recovered());
    EXPECT_EQ(ids_of(pipeline.boxes()), (std::vector<std::uint64_t>{1, 2}));
    EXPECT_EQ(pipeline.next_box_id(), 4u) << "id 3 would be handed out again";
    EXPECT_TRUE(pipeline.map().occupied_keys().empty());
  }
}

TEST(RecoverPipelineTest, OlderStateDirectoryKeepsTheCounterOfItsMapState) {
  test::TempDir dir;
  // An older cellmapd: the counter (9) only inside the map state (format 2), none in the snapshot.
  CellPipeline seen(CellPipelineConfig{});
  (void)seen.process(wall_sweep());
  const std::string current = seen.map_state();
  // Format 2: the counter line, the viewpoint line, the map (no change detector state).
  const std::size_t viewpoint = current.find('\n') + 1;
  const std::string older = "cellmap-map-state 2\n9\n" +
                            current.substr(viewpoint, current.find("cellmap-change ") - viewpoint) +
                            current.substr(current.find("cellmap-occupancy "));
  {
    VersionStore store(dir.path(), "cell");
    store.save(Environment("cell", 1, 1, boxes_with_ids({1, 2})), older);
  }
  const fs::path snapshot = dir.path() / "environment-00000000000000000001.json";
  std::string json = read_file(snapshot);
  const std::size_t key = json.find("\"next_box_id\"");
  ASSERT_NE(key, std::string::npos);
  json.erase(key, json.find('\n', key) + 1 - key);
  std::ofstream(snapshot, std::ios::trunc) << json;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    if (entry.path().filename().string().rfind("next-box-id-", 0) == 0) fs::remove(entry.path());
  }

  const VersionStore store(dir.path(), "cell");
  ASSERT_EQ(store.recovered().environment.version(), 1u) << store.recovered().problems.front();
  EXPECT_EQ(recover_pipeline(CellPipelineConfig{}, store.recovered()).next_box_id(), 9u);
}

}  // namespace
}  // namespace cellmap::daemon
