// SPDX-License-Identifier: Apache-2.0
// The optional layers: voxel runs against known answers, their bytes, and a writer that can tell whether
// anyone reads (real participants on loopback, domain 222).
#include "cellmap/transport/layers.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "cellmap/common/error.hpp"
#include "loopback.hpp"
#include "support/dds_domains.hpp"
#include "support/test_support.hpp"

namespace cellmap::transport {
namespace {

using namespace std::chrono_literals;
using test::kPatience;
constexpr std::uint32_t kDomain = test::domain::kLayers;

TEST(VoxelRunsTest, NeighboursAlongXJoinOneRun) {
  // Sorted by (z, y, x): a row of three, a gap, one more on that row, then one on the next row and level.
  const std::vector<VoxelRun> runs =
      voxel_runs({{-2, 0, 0}, {-1, 0, 0}, {0, 0, 0}, {5, 0, 0}, {5, 1, 0}, {-7, -3, 4}});
  const std::vector<VoxelRun> expected{{-2, 0, 0, 3}, {5, 0, 0, 1}, {5, 1, 0, 1}, {-7, -3, 4, 1}};
  EXPECT_EQ(runs, expected);
  EXPECT_EQ((VoxelLayer{"c", 1, 0, 0.02, runs}.voxel_count()), 6u);
}

TEST(VoxelRunsTest, RefusesUnsortedRepeatedOrOutOfRangeIndices) {
  EXPECT_NE(test::error_of([] {
              (void)voxel_runs({{1, 0, 0}, {0, 0, 0}});
            }).find("not sorted"),
            std::string::npos);
  EXPECT_NE(test::error_of([] {
              (void)voxel_runs({{1, 0, 0}, {1, 0, 0}});
            }).find("repeated"),
            std::string::npos);
  EXPECT_NE(test::error_of([] { (void)voxel_runs({{40000, 0, 0}}); }).find("int16"), std::string::npos);
}

TEST(LayerWireSizeTest, EightBytesPerRunAndFiftySixPerRegion) {
  VoxelLayer voxels{"cell-1", 3, 0, 0.02, std::vector<VoxelRun>(10, VoxelRun{1, 2, 3, 4})};
  const std::size_t ten_runs = wire_size(voxels);
  voxels.runs.resize(110);
  EXPECT_EQ(wire_size(voxels) - ten_runs, 800u);
  ChangeRegionLayer regions{"cell-1", 3, 0, std::vector<ChangeRegionBounds>(10)};
  const std::size_t ten_regions = wire_size(regions);
  regions.regions.resize(20);
  EXPECT_EQ(wire_size(regions) - ten_regions, 560u);  // six doubles and two uint32 each
}

TEST(LayerWireSizeTest, TwentyFourBytesPerOutlineRay) {
  SensorView view{"kinect", Eigen::Isometry3d::Identity(), FieldOfView{{}, true, 4.5}};
  view.field_of_view->outline_S.assign(4, Eigen::Vector3d::UnitZ());
  SensorLayer layer{"cell-1", 3, 0, {view}};
  const std::size_t four_rays = wire_size(layer);
  layer.views[0].field_of_view->outline_S.resize(14, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(wire_size(layer) - four_rays, 240u);  // x, y, z as doubles
}

// A tetrahedron: four vertices, four triangles.
std::shared_ptr<const TriangleMesh> tetrahedron() {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->vertices = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.2, 0}, {0, 0, 0.3}};
  mesh->triangles = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  return mesh;
}

TEST(LayerWireSizeTest, TwelveBytesPerMeshVertexAndTriangle) {
  RobotLayer layer{"cell-1", 3,
                   0,        1.0,
                   0.04,     {{"link_1", false, Eigen::Isometry3d::Identity(), MeshShape{tetrahedron()}}}};
  const std::size_t tetrahedron_size = wire_size(layer);
  auto bigger = std::make_shared<TriangleMesh>(*tetrahedron());
  bigger->vertices.resize(14, Eigen::Vector3d::Zero());
  bigger->triangles.resize(24, Eigen::Vector3i(0, 1, 2));
  layer.shapes[0].geometry = MeshShape{bigger};
  EXPECT_EQ(wire_size(layer) - tetrahedron_size, 10u * 12 + 20u * 12);  // 3 floats, 3 uint32
}

class LayerDdsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::use_loopback(); }
};

TEST_F(LayerDdsTest, WriterSeesReadersComeAndGoAndReadersGetWhatWasWritten) {
  dds::Participant daemon(kDomain);
  dds::Participant viewer(kDomain);
  LayerWriter writer(daemon, "cell-1");
  EXPECT_EQ(writer.readers(Layer::kVoxels), 0u);
  EXPECT_EQ(writer.readers_joined(Layer::kVoxels), 0u);
  {
    LayerReader reader(viewer, Layer::kVoxels);
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while (writer.readers(Layer::kVoxels) == 0 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(5ms);
    ASSERT_EQ(writer.readers(Layer::kVoxels), 1u);
    EXPECT_EQ(writer.readers_joined(Layer::kVoxels), 1u);
    EXPECT_EQ(writer.readers(Layer::kChangeRegions), 0u);  // each layer is asked for on its own

    const VoxelLayer sent{"cell-1", 9, 1234, 0.02, {{-5, 7, 0, 12}, {3, 3, 3, 1}}};
    writer.write(sent);
    std::vector<LayerMessage> received;
    while (received.empty() && std::chrono::steady_clock::now() < deadline) received = reader.take(100ms);
    ASSERT_EQ(received.size(), 1u);
    const auto& got = std::get<VoxelLayer>(received[0]);
    EXPECT_EQ(got.cell, "cell-1");
    EXPECT_EQ(got.sweep, 9u);
    EXPECT_EQ(got.stamp_ns, 1234);
    EXPECT_EQ(got.resolution, 0.02);
    EXPECT_EQ(got.runs, sent.runs);
  }
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (writer.readers(Layer::kVoxels) > 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(5ms);
  EXPECT_EQ(writer.readers(Layer::kVoxels), 0u);  // the reader left: the daemon stops writing
  EXPECT_EQ(writer.readers_joined(Layer::kVoxels), 1u);
}

TEST_F(LayerDdsTest, WriterRefusesAnotherCellsLayer) {
  dds::Participant daemon(kDomain);
  LayerWriter writer(daemon, "cell-1");
  EXPECT_NE(test::error_of([&] {
              writer.write(VoxelLayer{"cell-2", 1, 0, 0.02, {}});
            }).find("cell-2"),
            std::string::npos);
  EXPECT_NE(test::error_of([&] {
              writer.write(VoxelLayer{"cell-1", 1, 0, 0.0, {}});
            }).find("resolution"),
            std::string::npos);
}

// Every kind of shape, and a payload, comes through as written (mesh vertices as floats).
TEST_F(LayerDdsTest, ALayerCarryingMoreThanItsLimitIsRefusedAndTheNextOneArrives) {
  dds::Participant daemon(test::domain::kLayerLimits);
  dds::Participant viewer(test::domain::kLayerLimits);
  LayerWriter writer(daemon, "cell-1");
  LayerReader reader(viewer, Layer::kSensors);
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (writer.readers(Layer::kSensors) == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(5ms);
  ASSERT_EQ(writer.readers(Layer::kSensors), 1u);
  writer.write(SensorLayer{"cell-1", 1, 0, std::vector<SensorView>(kMaxSensors + 1, SensorView{"camera"})});
  EXPECT_TRUE(reader.take(500ms).empty()) << "a layer of 65 views was taken";
  writer.write(SensorLayer{"cell-1", 2, 0, std::vector<SensorView>(kMaxSensors, SensorView{"camera"})});
  std::vector<LayerMessage> received;
  while (received.empty() && std::chrono::steady_clock::now() < deadline) received = reader.take(100ms);
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(std::get<SensorLayer>(received[0]).sweep, 2u);
  EXPECT_EQ(std::get<SensorLayer>(received[0]).views.size(), kMaxSensors);
}

TEST_F(LayerDdsTest, RobotShapesComeThroughAsWritten) {
  dds::Participant daemon(test::domain::kRobotLayer);
  dds::Participant viewer(test::domain::kRobotLayer);
  LayerWriter writer(daemon, "cell-1");
  LayerReader reader(viewer, Layer::kRobot);
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (writer.readers(Layer::kRobot) == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(5ms);
  ASSERT_EQ(writer.readers(Layer::kRobot), 1u);
  EXPECT_EQ(writer.readers(Layer::kSensors), 0u);

  const Eigen::Isometry3d X_CG =
      Eigen::Translation3d(1.5, -0.45, 0.5) * Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized());
  const RobotLayer sent{
      "cell-1",
      7,
      99,
      1.1,
      0.04,
      {{"base_link", false, X_CG, MeshShape{tetrahedron()}},
       {"bridge", false, Eigen::Isometry3d(Eigen::Translation3d(1, 2, 2.6)), BoxShape{{0.15, 1.3, 0.15}}},
       {"link_2", false, X_CG.inverse(), CylinderShape{0.05, 0.2}},
       {"link_3", false, Eigen::Isometry3d::Identity(), SphereShape{0.07}},
       {"tool0", true, X_CG, BoxShape{{0.2, 0.15, 0.1}}}}};
  writer.write(sent);
  std::vector<LayerMessage> received;
  while (received.empty() && std::chrono::steady_clock::now() < deadline) received = reader.take(100ms);
  ASSERT_EQ(received.size(), 1u);
  const auto& got = std::get<RobotLayer>(received[0]);
  EXPECT_EQ(got.cell, "cell-1");
  EXPECT_EQ(got.sweep, 7u);
  EXPECT_EQ(got.stamp_ns, 99);
  EXPECT_EQ(got.padding_scale, 1.1);
  EXPECT_EQ(got.padding, 0.04);
  ASSERT_EQ(got.shapes.size(), sent.shapes.size());
  for (std::size_t i = 0; i < sent.shapes.size(); ++i) {
    EXPECT_EQ(got.shapes[i].link, sent.shapes[i].link);
    EXPECT_EQ(got.shapes[i].carried, sent.shapes[i].carried);
    EXPECT_TRUE(got.shapes[i].X_CG.isApprox(sent.shapes[i].X_CG, 1e-12)) << i;
    EXPECT_EQ(got.shapes[i].geometry.index(), sent.shapes[i].geometry.index()) << i;
  }
  const TriangleMesh& mesh = *std::get<MeshShape>(got.shapes[0].geometry).mesh;
  EXPECT_EQ(mesh.triangles, tetrahedron()->triangles);
  ASSERT_EQ(mesh.vertices.size(), 4u);
  EXPECT_TRUE(mesh.vertices[3].isApprox(Eigen::Vector3d(0, 0, 0.3), 1e-7));  // a float's precision
  EXPECT_EQ(std::get<BoxShape>(got.shapes[1].geometry).half_extents, Eigen::Vector3d(0.15, 1.3, 0.15));
  EXPECT_EQ(std::get<CylinderShape>(got.shapes[2].geometry).radius, 0.05);
  EXPECT_EQ(std::get<CylinderShape>(got.shapes[2].geometry).half_length, 0.2);
  EXPECT_EQ(std::get<SphereShape>(got.shapes[3].geometry).radius, 0.07);
  EXPECT_EQ(reader.rejected(), 0u);
}

TEST_F(LayerDdsTest, WriterRefusesAnInvalidRobotShape) {
  dds::Participant daemon(test::domain::kRobotLayer);
  LayerWriter writer(daemon, "cell-1");
  const RobotLayer flat{
      "cell-1", 1, 0, 1.0, 0.0, {{"ram", false, Eigen::Isometry3d::Identity(), BoxShape{{0.1, 0.0, 0.1}}}}};
  const std::string error = test::error_of([&] { writer.write(flat); });
  EXPECT_NE(error.find("cellmap/layer/robot: shapes[0]"), std::string::npos) << error;
  EXPECT_NE(error.find("positive"), std::string::npos) << error;
}

}  // namespace
}  // namespace cellmap::transport
