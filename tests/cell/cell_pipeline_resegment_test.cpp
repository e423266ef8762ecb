// SPDX-License-Identifier: Apache-2.0
// The cell pipeline's re-segmentation of a box that lost part of its voxels (CellPipeline::resegment on a map
// settled from a cloud of voxel centres, with the change given by hand): it shrinks in place when the box of
// what it still holds blocks little seen free space, and its extent is re-segmented when that box would
// block the space the removal freed or when something appeared beside it; and (sweeps of a box scene) an
// object whose box went before its removal was confirmed is reported when it comes back. Known answers,
// milliseconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "occupancy/box_scene.hpp"

namespace cellmap {
namespace {

constexpr double kVoxel = 0.02;  // cellmapd's default resolution

// cellmapd's shipped defaults with axis-aligned boxes (box bounds are then the known answers).
CellPipelineConfig config() {
  YamlMap root = YamlMap::load(CELLMAP_SOURCE_DIR "/config/cellmapd.yaml");
  CellPipelineConfig c = CellPipelineConfig::from_yaml(root);
  c.segment.box_kind = BoxKind::kAxisAligned;
  return c;
}

// The centres of the voxels filling [lo, hi) (metres, multiples of the voxel edge).
std::vector<Eigen::Vector3d> voxels(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  std::vector<Eigen::Vector3d> out;
  const Eigen::Vector3i n = ((hi - lo) / kVoxel).array().round().cast<int>();
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) out.push_back(lo + kVoxel * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
    }
  }
  return out;
}

Box box_of(std::uint64_t id, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, std::uint64_t points) {
  Box box;
  box.id = id;
  box.center = 0.5 * (lo + hi);
  box.half_extents = 0.5 * (hi - lo);
  box.points = points;
  return box;
}

// A map holding `occupied` (seen from above the table), the cell's boxes `boxes`, and the change of
// `vanished` (voxels now free) and `appeared` (voxels of `occupied` that are new) as one region.
class Table {
 public:
  Table(const std::vector<Eigen::Vector3d>& occupied, std::vector<Box> boxes)
      : pipeline_(config(), std::move(boxes), 10) {
    Cloud cloud;
    for (const Eigen::Vector3d& c : occupied) cloud.push_back(pcl::PointXYZ(c.x(), c.y(), c.z()));
    cloud.sensor_origin_ = Eigen::Vector4f(0.5f, 0.2f, 2.0f, 0.0f);
    EXPECT_EQ(pipeline_.settle_on(cloud), 0u);
  }

  [[nodiscard]] Resegmentation resegment(const std::vector<Eigen::Vector3d>& vanished,
                                         const std::vector<Eigen::Vector3d>& appeared = {}) const {
    ChangeRegion region;
    Region extent{Eigen::Vector3d::Constant(1e9), Eigen::Vector3d::Constant(-1e9)};
    const auto add = [&](const Eigen::Vector3d& c, std::vector<octomap::OcTreeKey>& keys) {
      keys.push_back(pipeline_.map().tree().coordToKey(c.x(), c.y(), c.z()));
      extent.min = extent.min.cwiseMin(c);
      extent.max = extent.max.cwiseMax(c);
    };
    for (const Eigen::Vector3d& c : vanished) add(c, region.vanished);
    for (const Eigen::Vector3d& c : appeared) add(c, region.appeared);
    region.bounds = extent.grown(0.5 * kVoxel + config().change.margin);
    ChangeSet changes;
    changes.regions.push_back(region);
    return pipeline_.resegment(changes);
  }

 private:
  CellPipeline pipeline_;
};

// Every voxel of `centres` wholly inside one box of `boxes`.
void expect_held(const std::vector<Box>& boxes, const std::vector<Eigen::Vector3d>& centres) {
  std::size_t outside = 0;
  for (const Eigen::Vector3d& c : centres) {
    const auto holds = [&](const Box& b) {
      return b.contains(c - Eigen::Vector3d::Constant(0.5 * kVoxel), 1e-6) &&
             b.contains(c + Eigen::Vector3d::Constant(0.5 * kVoxel), 1e-6);
    };
    outside += std::none_of(boxes.begin(), boxes.end(), holds) ? 1 : 0;
  }
  EXPECT_EQ(outside, 0u);
}

// A crate (0.3 × 0.2 × 0.06 m) taken off a table slab (1 × 0.4 × 0.04 m) that its box was joined with: the
// box shrinks to the slab, keeps its id (bounds IoU 0.4) and nothing is re-segmented.
TEST(CellPipelineResegmentTest, ABoxThatLostAnObjectShrinksInPlaceToWhatItStillHolds) {
  const std::vector<Eigen::Vector3d> slab = voxels({0, 0, 0.70}, {1.0, 0.4, 0.74});
  const std::vector<Eigen::Vector3d> crate = voxels({0.34, 0.1, 0.74}, {0.64, 0.3, 0.80});
  const Table table(slab, {box_of(3, {0, 0, 0.70}, {1.0, 0.4, 0.80}, slab.size() + crate.size())});

  const Resegmentation result = table.resegment(crate);
  EXPECT_EQ(result.evidence, 0u) << "the slab's voxels were re-segmented";
  const Reconciled& r = result.reconciled;
  ASSERT_EQ(r.modified.size(), 1u);
  EXPECT_TRUE(r.added.empty());
  EXPECT_TRUE(r.removed.empty());
  const Box& shrunk = r.modified[0];
  EXPECT_EQ(shrunk.id, 3u);
  EXPECT_EQ(shrunk.points, slab.size());
  const Region bounds = bounds_of(shrunk);
  EXPECT_NEAR(bounds.min.z(), 0.70, 1e-5);
  EXPECT_NEAR(bounds.max.z(), 0.74, 1e-5);
  EXPECT_NEAR(bounds.min.x(), 0.0, 1e-5);
  EXPECT_NEAR(bounds.max.x(), 1.0, 1e-5);
  expect_held(r.boxes, slab);
}

// A crate taken from between two slabs its box was joined with: the box of what is left would span the
// 0.4 m the crate freed, seen free from above, so the extent is re-segmented into a box per slab.
TEST(CellPipelineResegmentTest, ABoxThatWouldBlockTheFreedSpaceIsReSegmented) {
  std::vector<Eigen::Vector3d> slabs = voxels({0, 0, 0.70}, {0.3, 0.4, 0.74});
  const std::vector<Eigen::Vector3d> right = voxels({0.7, 0, 0.70}, {1.0, 0.4, 0.74});
  slabs.insert(slabs.end(), right.begin(), right.end());
  const std::vector<Eigen::Vector3d> crate = voxels({0.3, 0, 0.70}, {0.7, 0.4, 0.80});
  const Table table(slabs, {box_of(3, {0, 0, 0.70}, {1.0, 0.4, 0.80}, slabs.size() + crate.size())});

  const Resegmentation result = table.resegment(crate);
  EXPECT_EQ(result.evidence, slabs.size());
  const std::vector<Box>& boxes = result.reconciled.boxes;
  EXPECT_EQ(boxes.size(), 2u);
  expect_held(boxes, slabs);
  for (const Box& b : boxes) EXPECT_FALSE(b.contains({0.5, 0.2, 0.72})) << "box " << b.id << " spans the gap";
}

// The crate's voxels went while others appeared within change.margin of its box (the crate moved rather than
// went): the object changed, so the extent is re-segmented even though the box of what is left is tight.
TEST(CellPipelineResegmentTest, ABoxWithSomethingNewBesideItIsReSegmented) {
  std::vector<Eigen::Vector3d> occupied = voxels({0, 0, 0.70}, {1.0, 0.4, 0.74});
  const std::size_t slab = occupied.size();
  const std::vector<Eigen::Vector3d> crate = voxels({0.34, 0.1, 0.74}, {0.64, 0.3, 0.80});
  const std::vector<Eigen::Vector3d> moved = voxels({0.64, 0.1, 0.74}, {0.70, 0.3, 0.80});
  occupied.insert(occupied.end(), moved.begin(), moved.end());
  const Table table(occupied, {box_of(3, {0, 0, 0.70}, {1.0, 0.4, 0.80}, slab + crate.size())});

  const Resegmentation result = table.resegment(crate, moved);
  EXPECT_EQ(result.evidence, occupied.size());
  expect_held(result.reconciled.boxes, occupied);
}

// A crate put on the table is one new box, exactly its voxels' bounds: the table's box holds the rest.
TEST(CellPipelineResegmentTest, ANewObjectOneBoxHoldsTightlyIsThatBox) {
  std::vector<Eigen::Vector3d> occupied = voxels({0, 0, 0.70}, {1.0, 0.4, 0.74});
  const Box slab = box_of(3, {0, 0, 0.70}, {1.0, 0.4, 0.74}, occupied.size());
  const std::vector<Eigen::Vector3d> crate = voxels({0.34, 0.1, 0.74}, {0.64, 0.3, 0.80});
  occupied.insert(occupied.end(), crate.begin(), crate.end());
  const Table table(occupied, {slab});

  const Resegmentation result = table.resegment({}, crate);
  EXPECT_EQ(result.evidence, crate.size());
  EXPECT_TRUE(result.one_tight_box);
  ASSERT_EQ(result.reconciled.added.size(), 1u);
  const Box& added = result.reconciled.added.front();
  EXPECT_TRUE(added.center.isApprox(Eigen::Vector3d(0.49, 0.2, 0.77), 1e-6)) << added.center.transpose();
  EXPECT_TRUE(added.half_extents.isApprox(Eigen::Vector3d(0.15, 0.1, 0.03), 1e-3))
      << added.half_extents.transpose();
  expect_held(result.reconciled.boxes, occupied);
}

// A flat L put on the table: its one box would block a quarter of itself in space seen free, so it is
// segmented, and its two arms get a box each.
TEST(CellPipelineResegmentTest, ANewObjectOneBoxWouldHoldLooselyIsSegmented) {
  std::vector<Eigen::Vector3d> occupied = voxels({0, 0, 0.70}, {1.0, 0.4, 0.74});
  const Box slab = box_of(3, {0, 0, 0.70}, {1.0, 0.4, 0.74}, occupied.size());
  std::vector<Eigen::Vector3d> l_shape = voxels({0.2, 0.04, 0.74}, {0.6, 0.14, 0.80});
  const std::vector<Eigen::Vector3d> arm = voxels({0.2, 0.14, 0.74}, {0.3, 0.36, 0.80});
  l_shape.insert(l_shape.end(), arm.begin(), arm.end());
  occupied.insert(occupied.end(), l_shape.begin(), l_shape.end());
  const Table table(occupied, {slab});

  const Resegmentation result = table.resegment({}, l_shape);
  EXPECT_EQ(result.evidence, l_shape.size());
  EXPECT_FALSE(result.one_tight_box);
  EXPECT_EQ(result.reconciled.added.size(), 2u);
  expect_held(result.reconciled.boxes, occupied);
}

// A surface, rippled so that its box blocks a quarter of itself in space seen free (columns of voxels along
// x, 0–5 voxels high and back: low at x = 0.29, high at 0.79), x from `x0` to `x1`.
std::vector<Eigen::Vector3d> ripples(double x0, double x1) {
  std::vector<Eigen::Vector3d> out;
  for (double x = x0 + 0.5 * kVoxel; x < x1; x += kVoxel) {
    const int column = static_cast<int>(std::lround(x / kVoxel - 0.5) + 6) % 10;
    const double z = 0.70 + kVoxel * (0.5 + (column <= 5 ? column : 10 - column));
    for (double y = 0.5 * kVoxel; y < 0.4; y += kVoxel) out.emplace_back(x, y, z);
  }
  return out;
}

// The rippled surface comes into view a column further on each side of its box: the box grows to take
// both (they block little more than the box did), with no segmentation.
TEST(CellPipelineResegmentTest, ASurfaceComingIntoViewBesideItsBoxGrowsThatBox) {
  const std::vector<Eigen::Vector3d> seen = ripples(0.3, 0.78);
  const std::vector<Eigen::Vector3d> occupied = ripples(0.28, 0.8);
  std::vector<Eigen::Vector3d> appeared = ripples(0.28, 0.3);
  const std::vector<Eigen::Vector3d> right = ripples(0.78, 0.8);
  appeared.insert(appeared.end(), right.begin(), right.end());
  const Table table(occupied, {box_of(4, {0.3, 0, 0.70}, {0.78, 0.4, 0.82}, seen.size())});

  const Resegmentation result = table.resegment({}, appeared);
  EXPECT_EQ(result.evidence, occupied.size());
  EXPECT_TRUE(result.one_tight_box);
  ASSERT_EQ(result.reconciled.boxes.size(), 1u);
  const Box& grown = result.reconciled.boxes.front();
  EXPECT_EQ(grown.id, 4u);
  EXPECT_TRUE(grown.center.isApprox(Eigen::Vector3d(0.54, 0.2, 0.76), 1e-6)) << grown.center.transpose();
  EXPECT_TRUE(grown.half_extents.isApprox(Eigen::Vector3d(0.26, 0.2, 0.06), 1e-3))
      << grown.half_extents.transpose();
  expect_held(result.reconciled.boxes, occupied);
}

// Walls put up at both ends of the rippled surface: one box of them all would block the space over the
// whole surface, so they are segmented, and that space stays free.
TEST(CellPipelineResegmentTest, WallsBesideABoxThatOneBoxWouldHoldLooselyAreSegmented) {
  const std::vector<Eigen::Vector3d> surface = ripples(0.3, 0.78);
  std::vector<Eigen::Vector3d> occupied = surface, posts = voxels({0.22, 0, 0.70}, {0.3, 0.4, 1.0});
  const std::vector<Eigen::Vector3d> right = voxels({0.78, 0, 0.70}, {0.86, 0.4, 1.0});
  posts.insert(posts.end(), right.begin(), right.end());
  occupied.insert(occupied.end(), posts.begin(), posts.end());
  const Table table(occupied, {box_of(4, {0.3, 0, 0.70}, {0.78, 0.4, 0.82}, surface.size())});

  const Resegmentation result = table.resegment({}, posts);
  EXPECT_EQ(result.evidence, occupied.size());
  EXPECT_FALSE(result.one_tight_box);
  expect_held(result.reconciled.boxes, occupied);
  const Eigen::Vector3d over_the_surface(0.54, 0.2, 0.9);
  for (const Box& box : result.reconciled.boxes) EXPECT_FALSE(box.contains(over_the_surface)) << box.id;
}

// An object taken away and put back after a version (made by another change) dropped its box but before the
// change detector would have confirmed the removal: its return is reported and boxed like any new object,
// not taken for its voxels falling back to their confirmed state (which would leave it outside every box).
TEST(CellPipelineResegmentTest, AnObjectPutBackAfterItsBoxWentIsReportedAgain) {
  // A table (y down: its surface at y = 0.5) seen from 0.9 m above it, rays about 1 cm apart on it, so that
  // every voxel there is crossed each sweep; `object` hangs 10 cm above it (its box holds nothing else) all
  // along but for a few sweeps, `other` is put on the table far from it.
  const testing::AlignedBox table{{-1.0, 0.5, 0.0}, {1.0, 0.6, 2.5}};
  const testing::AlignedBox object{{-0.4, 0.2, 1.3}, {-0.2, 0.4, 1.5}},
      other{{0.2, 0.3, 1.3}, {0.4, 0.5, 1.5}};
  PinholeIntrinsics camera = testing::kinect_intrinsics(120, 90);
  camera.fx = camera.fy = 220.0;
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  X_CS.translate(Eigen::Vector3d(0.003, -0.4, 0.007));
  X_CS.rotate(Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitX()));
  CellPipelineConfig c = config();
  c.settle_sweeps = 2;
  CellPipeline pipeline(c, {}, 1);
  const auto sweep = [&](const std::vector<testing::AlignedBox>& scene) {
    Sweep s;
    s.scans.push_back(testing::render_scan(scene, X_CS, camera));
    return pipeline.process(s);
  };
  for (int n = 0; n < c.settle_sweeps + 3; ++n) (void)sweep({table, object});
  ASSERT_EQ(pipeline.voxels_outside_boxes(c.change.min_voxels), 0u);
  const Eigen::Vector3d top(-0.31, 0.21, 1.39);  // a voxel of the object's top
  const auto boxes_holding_top = [&] {
    const std::vector<Box>& boxes = pipeline.boxes();
    return std::count_if(boxes.begin(), boxes.end(), [&](const Box& b) { return b.contains(top); });
  };
  ASSERT_EQ(boxes_holding_top(), 1);

  // The object away: its voxels turn free in sweep `clear`, to be confirmed gone persist_sweeps − 1 sweeps
  // later. `other` is put down so that its change is reported in sweep `clear`: a version meanwhile, in
  // which the object's box, emptied, goes.
  const int clear = c.occupancy.sweeps_to_clear();
  const int put_down = clear - (c.occupancy.sweeps_to_occupy() + c.change.persist_sweeps - 2);
  ASSERT_GE(put_down, 1);
  SweepReport report;
  for (int n = 1; n <= clear; ++n) {
    report = sweep(n >= put_down ? std::vector<testing::AlignedBox>{table, other}
                                 : std::vector<testing::AlignedBox>{table});
    if (n < clear) {
      EXPECT_FALSE(report.change) << "a version in sweep " << n;
    }
  }
  ASSERT_TRUE(report.change) << "no version while the object's voxels were free but not confirmed so";
  ASSERT_EQ(pipeline.map().state(top), VoxelState::free);
  EXPECT_EQ(boxes_holding_top(), 0);

  // Back at once: one hit fills its voxels again (they have only just turned free). Reported as a change
  // persist_sweeps sweeps later, and boxed.
  int reported_after = 0;
  for (int n = 1; n <= c.change.persist_sweeps + 1 && reported_after == 0; ++n) {
    if (sweep({table, object, other}).change) reported_after = n;
  }
  EXPECT_EQ(reported_after, c.change.persist_sweeps) << "0: the object came back unreported";
  EXPECT_EQ(boxes_holding_top(), 1);
  EXPECT_EQ(pipeline.voxels_outside_boxes(c.change.min_voxels), 0u);
}

}  // namespace
}  // namespace cellmap
