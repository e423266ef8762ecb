// SPDX-License-Identifier: Apache-2.0
#include "cellmap/change/change_detector.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <sstream>
#include <string>

#include "cellmap/common/error.hpp"
#include "occupancy/box_scene.hpp"

namespace cellmap {
namespace {

using testing::AlignedBox;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A table top (y down: its surface at y = 0.5) with a back wall, seen from 0.9 m above the table, looking
// down.
std::vector<AlignedBox> table_scene() {
  return {{{-1.0, 0.5, 0.0}, {1.0, 0.6, 2.5}}, {{-1.0, -1.0, 2.2}, {1.0, 0.6, 2.3}}};
}

Eigen::Isometry3d camera_pose() {
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  X_CS.translate(Eigen::Vector3d(0.003, -0.4, 0.007));
  X_CS.rotate(Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitX()));
  return X_CS;
}

// Narrow-angle frames: rays about 1 cm apart on the table, so that every voxel there is crossed each sweep.
PinholeIntrinsics small_camera(int width, int height, double focal) {
  PinholeIntrinsics k = testing::kinect_intrinsics(width, height);
  k.fx = k.fy = focal;
  return k;
}

Sweep sweep_of(const std::vector<AlignedBox>& scene, const PinholeIntrinsics& camera,
               double noise_sigma = 0.0, std::mt19937* rng = nullptr,
               const Eigen::Isometry3d& X_CS = camera_pose()) {
  Sweep sweep;
  sweep.scans.push_back(testing::render_scan(scene, X_CS, camera, noise_sigma, rng));
  return sweep;
}

TEST(ChangeConfigTest, ReadsKeysAndNamesBadOnes) {
  YamlMap root =
      YamlMap::parse("change:\n  persist_sweeps: 5\n  margin: 0.1\n  min_voxels: 3\n", "cell.yaml");
  const ChangeConfig c = ChangeConfig::from_yaml(root.child("change"));
  EXPECT_EQ(c.persist_sweeps, 5);
  EXPECT_DOUBLE_EQ(c.margin, 0.1);
  EXPECT_EQ(c.min_voxels, 3);
  const ChangeConfig defaults;
  EXPECT_EQ(defaults.persist_sweeps, 3);
  EXPECT_DOUBLE_EQ(defaults.margin, 0.05);
  auto parse = [](const std::string& text) {
    YamlMap map = YamlMap::parse(text, "cell.yaml");
    return ChangeConfig::from_yaml(map.child("change"));
  };
  EXPECT_EQ(error_of([&] { (void)parse("change:\n  persist: 2\n"); }),
            "cell.yaml: change.persist: unknown key");
  EXPECT_EQ(error_of([&] { (void)parse("change:\n  persist_sweeps: 0\n"); }),
            "cell.yaml: change.persist_sweeps: must be an integer in [1, 1000], got 0");
  EXPECT_EQ(error_of([&] { (void)parse("change:\n  margin: -0.1\n"); }),
            "cell.yaml: change.margin: must be in [0, 10], got -0.1");
  ChangeConfig bad;
  bad.min_voxels = 0;
  EXPECT_EQ(error_of([&] { ChangeDetector{bad}; }),
            "change.min_voxels: must be an integer in [1, 1000000], got 0");
}

// Sensor noise alone must never produce a change region.
TEST(ChangeDetectorTest, ThousandNoiseOnlySweepsGiveNoRegion) {
  OccupancyMap map;
  ChangeConfig config;
  ChangeDetector detector(config);
  std::mt19937 rng(7);
  const double sigma = 0.004;  // Kinect-class depth noise at 1-1.5 m; 4 times that at the 0.5 m used here
  const std::vector<AlignedBox> scene = [] {
    std::vector<AlignedBox> s = table_scene();
    s.push_back({{-0.08, 0.35, 0.95}, {0.06, 0.5, 1.1}});
    return s;
  }();
  // Close above the table (short rays keep 1 000 sweeps fast): 0.5 m up, looking 52° down at the box, with a
  // wide lens (about 2 pixels per voxel), so that many surface voxels flicker between sweeps.
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  X_CS.translate(Eigen::Vector3d(0.003, 0.0, 0.607));
  X_CS.rotate(Eigen::AngleAxisd(-0.9, Eigen::Vector3d::UnitX()));
  const PinholeIntrinsics camera = small_camera(48, 36, 45.0);
  // The first sweeps show the scene itself, which is a change from the empty map, and for 2 · persist_sweeps
  // sweeps after that the parts of it that fill in later.
  std::size_t initial = 0;
  for (int i = 0; i < 3 * config.persist_sweeps; ++i) {
    initial += detector.update(map.integrate(sweep_of(scene, camera, sigma, &rng, X_CS)), map).regions.size();
  }
  EXPECT_GE(initial, 1u);
  std::size_t regions = 0, flips = 0;
  for (int i = 0; i < 1000; ++i) {
    const OccupancyUpdate update = map.integrate(sweep_of(scene, camera, sigma, &rng, X_CS));
    flips += update.appeared.size() + update.vanished.size();
    const ChangeSet changes = detector.update(update, map);
    regions += changes.regions.size();
    for (const ChangeRegion& r : changes.regions) {
      ADD_FAILURE() << "sweep " << changes.sweep << ": region " << r.bounds.min.transpose() << " .. "
                    << r.bounds.max.transpose() << " with " << r.appeared.size() << " appeared, "
                    << r.vanished.size() << " vanished";
    }
  }
  EXPECT_EQ(regions, 0u);
  EXPECT_GT(flips, 0u) << "the noise should make some voxels flip, else this test proves nothing";
  std::printf("noise-only: %zu voxel flips over 1000 sweeps, %zu regions\n", flips, regions);
}

TEST(ChangeDetectorTest, AddedAndRemovedBoxGiveOneRegionEach) {
  OccupancyMap map;
  ChangeConfig config;
  ChangeDetector detector(config);
  const PinholeIntrinsics camera = small_camera(120, 90, 220.0);
  std::vector<AlignedBox> scene = table_scene();
  for (int i = 0; i < 8; ++i) (void)detector.update(map.integrate(sweep_of(scene, camera)), map);

  const AlignedBox box{{-0.15, 0.3, 1.21}, {0.1, 0.5, 1.45}};
  scene.push_back(box);
  // Its voxels were free at the lower clamp: occupied after sweeps_to_occupy() sweeps, reported
  // persist_sweeps - 1 sweeps later, as one region around the box.
  const int add_sweep = map.config().sweeps_to_occupy() + config.persist_sweeps - 1;  // 5 by default
  std::vector<ChangeSet> after_add;
  for (int i = 1; i <= add_sweep + 2; ++i)
    after_add.push_back(detector.update(map.integrate(sweep_of(scene, camera)), map));
  for (std::size_t i = 0; i < after_add.size(); ++i) {
    ASSERT_EQ(after_add[i].regions.size(), int(i) + 1 == add_sweep ? 1u : 0u)
        << "sweep " << i + 1 << " after adding";
  }
  const ChangeRegion& added = after_add[std::size_t(add_sweep) - 1].regions[0];
  EXPECT_TRUE(added.bounds.contains(box.min_C)) << added.bounds.min.transpose();
  EXPECT_TRUE(added.bounds.contains(box.max_C)) << added.bounds.max.transpose();
  EXPECT_TRUE(added.vanished.empty());
  EXPECT_GT(added.appeared.size(), 50u);
  // Not much bigger than the box: its visible faces plus the margin.
  EXPECT_LT((added.bounds.max - added.bounds.min - (box.max_C - box.min_C)).maxCoeff(),
            2 * config.margin + 0.05);

  // Let the box saturate, then take it away.
  for (int i = 0; i < 6; ++i)
    ASSERT_TRUE(detector.update(map.integrate(sweep_of(scene, camera)), map).empty());
  scene.pop_back();
  const int expected_sweep = map.config().sweeps_to_clear() + config.persist_sweeps - 1;  // 11 by default
  for (int i = 1; i <= expected_sweep + 3; ++i) {
    const ChangeSet changes = detector.update(map.integrate(sweep_of(scene, camera)), map);
    if (i != expected_sweep) {
      EXPECT_TRUE(changes.empty()) << "sweep " << i << " after removing";
      continue;
    }
    ASSERT_EQ(changes.regions.size(), 1u);
    const ChangeRegion& removed = changes.regions[0];
    EXPECT_TRUE(removed.appeared.empty());
    EXPECT_GT(removed.vanished.size(), 50u);
    EXPECT_TRUE(removed.bounds.contains(box.min_C + Eigen::Vector3d(0, 0.02, 0)));
    EXPECT_TRUE(removed.bounds.contains(box.max_C - Eigen::Vector3d(0, 0.02, 0)));
  }
  EXPECT_EQ(detector.pending(), 0u);
}

// A box taken away and put back before its removal is confirmed: its voxels fall back to their confirmed
// state and nothing is reported. After accept_vanished (its voxels free, their vanish not reported but taken
// as confirmed), putting it back is reported as an appearance, persist_sweeps sweeps later.
TEST(ChangeDetectorTest, ABoxPutBackIsReportedOnlyAfterItsVanishWasAccepted) {
  const PinholeIntrinsics camera = small_camera(120, 90, 220.0);
  const AlignedBox box{{-0.15, 0.3, 1.21}, {0.1, 0.5, 1.45}};
  std::vector<AlignedBox> with_box = table_scene();
  with_box.push_back(box);
  for (const bool accept : {false, true}) {
    OccupancyMap map;
    ChangeConfig config;
    ChangeDetector detector(config);
    for (int i = 0; i < 10; ++i) (void)detector.update(map.integrate(sweep_of(with_box, camera)), map);
    // Away until its voxels are free in the map (sweeps_to_clear sweeps), not longer: no vanish confirmed
    // (the table it hid appears meanwhile).
    for (int i = 0; i < map.config().sweeps_to_clear(); ++i) {
      for (const ChangeRegion& r :
           detector.update(map.integrate(sweep_of(table_scene(), camera)), map).regions)
        ASSERT_TRUE(r.vanished.empty()) << "sweep " << i + 1 << " after taking the box away";
    }
    const std::vector<octomap::OcTreeKey> pending = detector.pending_vanished();
    ASSERT_GT(pending.size(), 50u);
    if (accept) detector.accept_vanished(pending);
    EXPECT_EQ(detector.pending_vanished().empty(), accept);
    std::size_t regions = 0;
    int reported_at = 0;
    for (int i = 1; i <= config.persist_sweeps + 2; ++i) {
      const ChangeSet changes = detector.update(map.integrate(sweep_of(with_box, camera)), map);
      regions += changes.regions.size();
      if (!changes.empty() && reported_at == 0) reported_at = i;
    }
    EXPECT_EQ(regions, accept ? 1u : 0u) << (accept ? "accepted" : "not accepted");
    EXPECT_EQ(reported_at, accept ? config.persist_sweeps : 0);
  }
}

// A map and its detector saved while a new box's flips wait for confirmation (as a daemon saves them with a
// version) and read back: the copy reports the box at the same sweep and as the same region as the original.
// A fresh detector on the saved map never reports it: the voxels do not flip again.
TEST(ChangeDetectorTest, AStateReadBackConfirmsThePendingFlipsAsIfUninterrupted) {
  OccupancyMap map;
  const ChangeConfig config;
  ChangeDetector detector(config);
  const PinholeIntrinsics camera = small_camera(120, 90, 220.0);
  std::vector<AlignedBox> scene = table_scene();
  for (int i = 0; i < 8; ++i) (void)detector.update(map.integrate(sweep_of(scene, camera)), map);
  scene.push_back({{-0.15, 0.3, 1.21}, {0.1, 0.5, 1.45}});
  const int seen = map.config().sweeps_to_occupy();  // the box's voxels flipped in the last of these
  for (int i = 0; i < seen; ++i)
    ASSERT_TRUE(detector.update(map.integrate(sweep_of(scene, camera)), map).empty());
  ASSERT_GT(detector.pending(), 50u);

  std::stringstream map_state, detector_state;
  map.write(map_state);
  detector.write(detector_state);
  OccupancyMap map_copy, map_fresh;
  map_copy.read(map_state);
  map_state.seekg(0);
  map_fresh.read(map_state);
  ChangeDetector copy(config), fresh(config);
  copy.read(detector_state);
  EXPECT_EQ(copy.pending(), detector.pending());

  std::vector<std::uint64_t> original_sweeps, copy_sweeps;
  for (int i = 0; i < config.persist_sweeps + 2; ++i) {
    const Sweep sweep = sweep_of(scene, camera);
    const ChangeSet original = detector.update(map.integrate(sweep), map);
    const ChangeSet copied = copy.update(map_copy.integrate(sweep), map_copy);
    EXPECT_TRUE(fresh.update(map_fresh.integrate(sweep), map_fresh).empty()) << "sweep " << i + 1;
    ASSERT_EQ(copied.sweep, original.sweep);
    ASSERT_EQ(copied.regions.size(), original.regions.size()) << "sweep " << original.sweep;
    for (std::size_t r = 0; r < original.regions.size(); ++r) {
      EXPECT_EQ(copied.regions[r].appeared, original.regions[r].appeared);
      EXPECT_EQ(copied.regions[r].vanished, original.regions[r].vanished);
      EXPECT_EQ(copied.regions[r].bounds.min, original.regions[r].bounds.min);
      EXPECT_EQ(copied.regions[r].bounds.max, original.regions[r].bounds.max);
    }
    if (!original.empty()) original_sweeps.push_back(original.sweep);
  }
  EXPECT_EQ(original_sweeps,
            (std::vector<std::uint64_t>{8u + std::uint64_t(seen + config.persist_sweeps - 1)}));
}

TEST(ChangeDetectorTest, AMalformedStateIsRefusedAndChangesNothing) {
  OccupancyMap map;
  ChangeConfig config;
  config.persist_sweeps = 3;
  ChangeDetector detector(config);
  OccupancyUpdate appear;
  appear.appeared.push_back(map.tree().coordToKey(0.5, 0.5, 0.5));
  (void)detector.update(appear, map);
  std::stringstream saved;
  detector.write(saved);
  EXPECT_EQ(saved.str(), "cellmap-change 1 1 0\n32793 32793 32793 0 1\n");
  const auto read = [&](const std::string& text) {
    return error_of([&] {
      std::istringstream in(text);
      detector.read(in);
    });
  };
  EXPECT_EQ(read("cellmap-map 1 1 0\n"), "change detector state: bad header line");
  EXPECT_EQ(read("cellmap-change 1 2 0\n1 2 3 0 1\n"), "change detector state: bad pending voxel 2");
  EXPECT_EQ(read("cellmap-change 1 1 0\n65536 2 3 0 1\n"), "change detector state: bad pending voxel 1");
  EXPECT_EQ(read("cellmap-change 1 1 0\n1 2 3 2 1\n"), "change detector state: bad pending voxel 1");
  EXPECT_EQ(read("cellmap-change 1 1 0\n1 2 3 0 -1\n"), "change detector state: bad pending voxel 1");
  EXPECT_EQ(read("cellmap-change 1 0 1\n1 2 3 2\n"), "change detector state: bad reported voxel 1");
  EXPECT_EQ(detector.pending(), 1u);  // unchanged by the refusals
  EXPECT_EQ(read(saved.str()), "");
  EXPECT_EQ(detector.pending(), 1u);
}

TEST(ChangeDetectorTest, FlipBackBeforePersistingIsForgotten) {
  OccupancyMap map;
  ChangeConfig config;
  config.persist_sweeps = 2;
  config.min_voxels = 1;
  ChangeDetector detector(config);
  // Synthetic flips: one voxel appears and vanishes again before it has persisted.
  const octomap::OcTreeKey key = map.tree().coordToKey(0.5, 0.5, 0.5);
  OccupancyUpdate appear, vanish, nothing;
  appear.appeared.push_back(key);
  vanish.vanished.push_back(key);
  EXPECT_TRUE(detector.update(appear, map).empty());
  EXPECT_EQ(detector.pending(), 1u);
  EXPECT_TRUE(detector.update(vanish, map).empty());
  EXPECT_EQ(detector.pending(), 0u);
  EXPECT_TRUE(detector.update(nothing, map).empty());
  // Persisting twice counts: one region of one voxel, bounds = voxel ± margin.
  EXPECT_TRUE(detector.update(appear, map).empty());
  const ChangeSet changes = detector.update(nothing, map);
  ASSERT_EQ(changes.regions.size(), 1u);
  EXPECT_EQ(changes.sweep, 5u);
  const double lo = map.centre(key).x() - 0.01 - config.margin;
  EXPECT_NEAR(changes.regions[0].bounds.min.x(), lo, 1e-9);
  EXPECT_NEAR(changes.regions[0].bounds.max.x() - changes.regions[0].bounds.min.x(), 0.02 + 2 * config.margin,
              1e-9);
}

TEST(ChangeDetectorTest, ConnectedVoxelsFormOneRegionSeparateOnesTwo) {
  OccupancyMap map;
  ChangeConfig config;
  config.persist_sweeps = 1;
  config.min_voxels = 1;
  config.margin = 0.0;
  ChangeDetector detector(config);
  OccupancyUpdate update;
  const auto& tree = map.tree();
  for (const double x : {0.01, 0.03, 0.05})
    update.appeared.push_back(tree.coordToKey(x, x, x));  // diagonal: 26-connected
  update.appeared.push_back(tree.coordToKey(0.51, 0.01, 0.01));
  const ChangeSet changes = detector.update(update, map);
  ASSERT_EQ(changes.regions.size(), 2u);
  EXPECT_EQ(changes.regions[0].appeared.size(), 3u);
  EXPECT_NEAR(changes.regions[0].bounds.min.x(), 0.0, 1e-9);
  EXPECT_NEAR(changes.regions[0].bounds.max.x(), 0.06, 1e-9);
  EXPECT_EQ(changes.regions[1].appeared.size(), 1u);
}

}  // namespace
}  // namespace cellmap
