// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/environment_tracker.hpp"

#include <gtest/gtest.h>

#include "scene_steps.hpp"

namespace cellmap::transport {
namespace {

// Versions 0..n of the test sequence, and the deltas between neighbours.
struct History {
  std::vector<Environment> versions;
  std::vector<EnvironmentDelta> deltas;  // deltas[i]: version i -> i + 1
  explicit History(int n) {
    versions.push_back(Environment("cell-a"));
    for (int v = 1; v <= n; ++v) {
      versions.push_back(test::next_environment(versions.back(), v, v * 100));
      deltas.push_back(diff(versions[v - 1], versions[v]));
    }
  }
};

TEST(EnvironmentTrackerTest, FirstSnapshotThenDeltasInOrder) {
  const History h(5);
  EnvironmentTracker tracker("cell-a");
  EXPECT_TRUE(tracker.needs_snapshot());
  // A delta before any snapshot is held until the snapshot it continues arrives.
  EXPECT_TRUE(tracker.on_delta(h.deltas[2]).empty());
  auto updates = tracker.on_snapshot(h.versions[2]);
  ASSERT_EQ(updates.size(), 2u);
  EXPECT_TRUE(updates[0].from_snapshot);
  EXPECT_EQ(updates[0].delta.from_version, 0u);
  EXPECT_EQ(updates[0].delta.added.size(), h.versions[2].boxes().size());
  EXPECT_FALSE(updates[1].from_snapshot);
  EXPECT_EQ(updates[1].environment, h.versions[3]);
  EXPECT_FALSE(tracker.needs_snapshot());
  updates = tracker.on_delta(h.deltas[3]);
  ASSERT_EQ(updates.size(), 1u);
  EXPECT_EQ(updates[0].environment, h.versions[4]);
  EXPECT_EQ(updates[0].delta.added.size() + updates[0].delta.modified.size(), 1u);
  EXPECT_EQ(tracker.stats().deltas_applied, 2u);
  EXPECT_EQ(tracker.stats().snapshots_applied, 1u);
  EXPECT_EQ(tracker.stats().gaps, 0u);
}

TEST(EnvironmentTrackerTest, OldDuplicateAndForeignSamplesAreIgnored) {
  const History h(4);
  EnvironmentTracker tracker("cell-a");
  (void)tracker.on_snapshot(h.versions[3]);
  EXPECT_TRUE(tracker.on_snapshot(h.versions[3]).empty());
  EXPECT_TRUE(tracker.on_snapshot(h.versions[2]).empty());
  EXPECT_TRUE(tracker.on_delta(h.deltas[1]).empty());
  EXPECT_TRUE(tracker.on_snapshot(Environment("cell-b", 9, 0, {})).empty());
  EnvironmentDelta foreign = h.deltas[3];
  foreign.cell = "cell-b";
  EXPECT_TRUE(tracker.on_delta(foreign).empty());
  EXPECT_EQ(tracker.environment()->version(), 3u);
  EXPECT_FALSE(tracker.needs_snapshot());
  EXPECT_EQ(tracker.stats().other_cells, 2u);  // the foreign snapshot and delta, not the old own samples
}

TEST(EnvironmentTrackerTest, GapHoldsDeltasUntilASnapshotResyncs) {
  const History h(8);
  EnvironmentTracker tracker("cell-a");
  (void)tracker.on_snapshot(h.versions[1]);
  (void)tracker.on_delta(h.deltas[1]);  // 1 -> 2
  // 2 -> 3 and 3 -> 4 are lost; 4 -> 5 and 5 -> 6 arrive.
  EXPECT_TRUE(tracker.on_delta(h.deltas[4]).empty());
  EXPECT_TRUE(tracker.on_delta(h.deltas[5]).empty());
  EXPECT_TRUE(tracker.needs_snapshot());
  EXPECT_EQ(tracker.stats().gaps, 2u);
  EXPECT_EQ(tracker.environment()->version(), 2u);
  // The snapshot of 4 bridges the gap; the held deltas then continue to 6.
  const auto updates = tracker.on_snapshot(h.versions[4]);
  ASSERT_EQ(updates.size(), 3u);
  EXPECT_TRUE(updates[0].from_snapshot);
  EXPECT_EQ(updates[0].delta.from_version, 2u);
  EXPECT_EQ(apply(h.versions[2], updates[0].delta), h.versions[4]);
  EXPECT_EQ(updates[2].environment, h.versions[6]);
  EXPECT_FALSE(tracker.needs_snapshot());
  EXPECT_EQ(tracker.stats().snapshots_applied, 2u);
}

TEST(EnvironmentTrackerTest, DeltaFromVersionZeroIsASnapshot) {
  const History h(6);
  EnvironmentTracker tracker("cell-a");
  (void)tracker.on_snapshot(h.versions[2]);
  // A restarted publisher sends version 5 whole: the copy jumps there without waiting for the snapshot topic.
  const auto updates = tracker.on_delta(diff(h.versions[0], h.versions[5]));
  ASSERT_EQ(updates.size(), 1u);
  EXPECT_EQ(updates[0].delta.from_version, 2u);
  EXPECT_EQ(updates[0].environment, h.versions[5]);
  EXPECT_FALSE(tracker.needs_snapshot());
  EXPECT_EQ(tracker.stats().gaps, 0u);
}

TEST(EnvironmentTrackerTest, ContradictingDeltaWaitsForSnapshot) {
  const History h(3);
  EnvironmentTracker tracker("cell-a");
  (void)tracker.on_snapshot(h.versions[1]);
  EnvironmentDelta bad = h.deltas[1];
  bad.added = {h.versions[1].boxes().front()};  // re-adds an id the copy has: a reused version number
  bad.modified.clear();
  EXPECT_TRUE(tracker.on_delta(bad).empty());
  EXPECT_EQ(tracker.stats().rejected, 1u);
  EXPECT_TRUE(tracker.needs_snapshot());
  EXPECT_TRUE(tracker.on_delta(h.deltas[2]).empty());  // no delta is trusted until a snapshot
  const auto updates = tracker.on_snapshot(h.versions[3]);
  ASSERT_EQ(updates.size(), 1u);
  EXPECT_EQ(*tracker.environment(), h.versions[3]);
  EXPECT_FALSE(tracker.needs_snapshot());
}

// A snapshot forged far ahead (or a publisher whose state was wiped, starting again at version 1) must not
// freeze the copy: once the publisher's snapshots go on below the local version, the copy follows them.
// The daemon's state directory was wiped: it counts from 1 again, below the copy of its earlier life.
TEST(EnvironmentTrackerTest, ACopyAheadOfThePublisherFollowsItsSnapshotsBack) {
  const History h(6);
  EnvironmentTracker tracker("cell-a");
  const Environment earlier_life("cell-a", 5000, 0, {});
  ASSERT_EQ(tracker.on_snapshot(earlier_life).size(), 1u);
  // In sync, a subscriber reads deltas only: the publisher's next ones arrive below the local version.
  EXPECT_TRUE(tracker.on_delta(h.deltas[1]).empty());
  EXPECT_TRUE(tracker.on_delta(h.deltas[1]).empty()) << "a duplicate counts once";
  EXPECT_TRUE(tracker.on_delta(h.deltas[2]).empty());
  EXPECT_FALSE(tracker.needs_snapshot());
  EXPECT_TRUE(tracker.on_delta(h.deltas[3]).empty());
  EXPECT_TRUE(tracker.needs_snapshot()) << "three versions below the local one";
  const auto updates = tracker.on_snapshot(h.versions[4]);
  ASSERT_EQ(updates.size(), 1u);
  EXPECT_TRUE(updates[0].from_snapshot);
  EXPECT_EQ(updates[0].delta.from_version, 5000u);
  EXPECT_EQ(updates[0].delta.to_version, 4u);
  EXPECT_EQ(updates[0].delta.added.size(), h.versions[4].boxes().size());
  EXPECT_EQ(*tracker.environment(), h.versions[4]);
  EXPECT_EQ(tracker.stats().went_back, 1u);
  // From there on deltas apply as usual.
  ASSERT_EQ(tracker.on_delta(h.deltas[4]).size(), 1u);
  EXPECT_EQ(*tracker.environment(), h.versions[5]);
  EXPECT_FALSE(tracker.needs_snapshot());
}

TEST(EnvironmentTrackerTest, AVersionFarAheadIsRefusedOnceACopyExists) {
  const History h(4);
  EnvironmentTracker tracker("cell-a");
  (void)tracker.on_snapshot(h.versions[1]);
  EXPECT_TRUE(tracker.on_snapshot(Environment("cell-a", 1 + kMaxVersionJump + 1, 0, {})).empty());
  EnvironmentDelta forged_delta{"cell-a", 1, UINT64_MAX, 0, {}, {}, {}};
  EXPECT_TRUE(tracker.on_delta(forged_delta).empty());
  EXPECT_EQ(tracker.stats().implausible, 2u);
  EXPECT_EQ(*tracker.environment(), h.versions[1]);
  EXPECT_FALSE(tracker.needs_snapshot());
  ASSERT_EQ(tracker.on_delta(h.deltas[1]).size(), 1u);
  // A jump of exactly kMaxVersionJump is still taken (a long-running daemon restarted far above).
  EXPECT_EQ(tracker.on_snapshot(Environment("cell-a", 2 + kMaxVersionJump, 0, {})).size(), 1u);
}

// A late joiner whose first copy is a forged snapshot far ahead: the daemon's versions go on below it, and
// the forger's kept snapshot, arriving again while the copy follows the daemon back, does not hold it up
// there.
TEST(EnvironmentTrackerTest, AFirstCopyForgedFarAheadFollowsTheDaemonBackPastTheForgersSnapshot) {
  const History h(6);
  EnvironmentTracker tracker("cell-a");
  const Environment forged("cell-a", UINT64_MAX - 8, 0, {});
  ASSERT_EQ(tracker.on_snapshot(forged).size(), 1u);
  for (int v : {2, 3, 4}) EXPECT_TRUE(tracker.on_delta(h.deltas[static_cast<std::size_t>(v)]).empty());
  ASSERT_TRUE(tracker.needs_snapshot());
  EXPECT_TRUE(tracker.on_snapshot(forged).empty()) << "the forger's snapshot, delivered again";
  EXPECT_EQ(tracker.on_snapshot(h.versions[5]).size(), 1u);
  EXPECT_EQ(*tracker.environment(), h.versions[5]);
  EXPECT_TRUE(tracker.on_snapshot(forged).empty());
  EXPECT_EQ(tracker.stats().implausible, 1u);
  EXPECT_EQ(*tracker.environment(), h.versions[5]);
}

TEST(EnvironmentTrackerTest, OldSnapshotsArrivingLateDoNotTurnTheCopyBack) {
  const History h(6);
  EnvironmentTracker tracker("cell-a");
  (void)tracker.on_snapshot(h.versions[5]);
  for (int v : {1, 2, 5, 3, 4, 6, 2, 3}) (void)tracker.on_snapshot(h.versions[static_cast<std::size_t>(v)]);
  EXPECT_EQ(*tracker.environment(), h.versions[6]);
  EXPECT_EQ(tracker.stats().went_back, 0u);
}

}  // namespace
}  // namespace cellmap::transport
