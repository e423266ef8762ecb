// SPDX-License-Identifier: Apache-2.0
// What the viewer tells its pages: the messages of ViewState for versions, status and layers, and the state a
// page gets when it connects.
#include "cellmap/view/view_state.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>

namespace cellmap::view {
namespace {

using nlohmann::json;

Box make_box(std::uint64_t id, double x) {
  Box box;
  box.id = id;
  box.center = {x, 0.5, 0.25};
  box.half_extents = {0.1, 0.2, 0.25};
  box.points = 10 * id;
  return box;
}

// Feeds env_before → env_after to `state` as the subscriber's callback would; returns the parsed message.
json step(ViewState& state, const Environment& before, const Environment& after, std::int64_t received = 7) {
  return json::parse(state.on_version(after, diff(before, after), received));
}

json box_in(const json& cell, std::uint64_t id) {
  for (const json& box : cell["boxes"])
    if (box["id"] == id) return box;
  return nullptr;
}

TEST(ViewStateTest, VersionMessageCarriesTheDeltaAndTheVersionThatChangedEachBox) {
  ViewState state(3, "");
  const Environment v0("cell-a");
  const Environment v1("cell-a", 1, 100, {make_box(1, 0.0), make_box(2, 1.0)});
  const json first = step(state, v0, v1);
  EXPECT_EQ(first["type"], "version");
  EXPECT_EQ(first["cell"], "cell-a");
  EXPECT_EQ(first["from_version"], 0);
  EXPECT_EQ(first["to_version"], 1);
  EXPECT_EQ(first["stamp_ns"], 100);
  EXPECT_EQ(first["received_ns"], 7);
  ASSERT_EQ(first["added"].size(), 2u);
  EXPECT_EQ(first["added"][0]["changed_in"], 1);  // version 1 added everything it holds
  EXPECT_EQ(first["added"][1]["half_extents"], json::array({0.1, 0.2, 0.25}));
  EXPECT_EQ(first["added"][1]["rotation"], json::array({1.0, 0.0, 0.0, 0.0}));
  EXPECT_EQ(first["added"][1]["points"], 20);

  Box moved = make_box(2, 1.5);
  const Environment v2("cell-a", 2, 200, {make_box(1, 0.0), moved, make_box(3, 2.0)});
  const json second = step(state, v1, v2);
  ASSERT_EQ(second["added"].size(), 1u);
  EXPECT_EQ(second["added"][0]["id"], 3);
  ASSERT_EQ(second["modified"].size(), 1u);
  EXPECT_EQ(second["modified"][0]["center"][0], 1.5);
  EXPECT_EQ(second["modified"][0]["changed_in"], 2);

  const Environment v3("cell-a", 3, 300, {make_box(1, 0.0), moved});
  const json third = step(state, v2, v3);
  EXPECT_EQ(third["removed"], json::array({3}));

  const json cell = json::parse(state.state())["cells"][0];
  EXPECT_EQ(cell["version"], 3);
  EXPECT_EQ(cell["stamp_ns"], 300);
  ASSERT_EQ(cell["boxes"].size(), 2u);
  EXPECT_EQ(box_in(cell, 1)["changed_in"], 1);
  EXPECT_EQ(box_in(cell, 2)["changed_in"], 2);
  ASSERT_EQ(cell["timeline"].size(), 3u);
  EXPECT_EQ(cell["timeline"][1], json({{"from_version", 1},
                                       {"to_version", 2},
                                       {"stamp_ns", 200},
                                       {"received_ns", 7},
                                       {"added", 1},
                                       {"modified", 1},
                                       {"removed", 0}}));
}

TEST(ViewStateTest, BoxesOfALateJoinersFirstCopyHaveNoKnownVersion) {
  ViewState state(0, "");
  const Environment v7("cell-a", 7, 700, {make_box(4, 0.0)});
  const json first = step(state, Environment("cell-a"), v7);
  EXPECT_TRUE(first["added"][0]["changed_in"].is_null());
  const Environment v8("cell-a", 8, 800, {make_box(4, 0.0), make_box(5, 1.0)});
  step(state, v7, v8);
  const json cell = json::parse(state.state())["cells"][0];
  EXPECT_TRUE(box_in(cell, 4)["changed_in"].is_null());
  EXPECT_EQ(box_in(cell, 5)["changed_in"], 8);
}

TEST(ViewStateTest, EveryBoxSaysWhichSpaceItHolds) {
  // The page draws unknown boxes grey and lets them be hidden: it learns which they are from "space".
  ViewState state(0, "");
  Box unknown = make_box(2, 1.0);
  unknown.space = BoxSpace::kUnknown;
  const Environment v1("cell-a", 1, 100, {make_box(1, 0.0), unknown});
  const json first = step(state, Environment("cell-a"), v1);
  ASSERT_EQ(first["added"].size(), 2u);
  EXPECT_EQ(first["added"][0]["space"], "occupied");
  EXPECT_EQ(first["added"][1]["space"], "unknown");
  const json cell = json::parse(state.state())["cells"][0];
  EXPECT_EQ(box_in(cell, 1)["space"], "occupied");
  EXPECT_EQ(box_in(cell, 2)["space"], "unknown");
}

TEST(ViewStateTest, TimelineKeepsTheNewestVersions) {
  ViewState state(0, "", 3);
  Environment env("cell-a");
  for (std::uint64_t v = 1; v <= 5; ++v) {
    const Environment next("cell-a", v, static_cast<std::int64_t>(v), {make_box(v, 0.1 * v)});
    step(state, env, next);
    env = next;
  }
  const json timeline = json::parse(state.state())["cells"][0]["timeline"];
  ASSERT_EQ(timeline.size(), 3u);
  EXPECT_EQ(timeline[0]["to_version"], 3);
  EXPECT_EQ(timeline[2]["to_version"], 5);
}

TEST(ViewStateTest, StatusThenDaemonGoneKeepsTheLastReport) {
  ViewState state(5, "cell-a");
  EXPECT_FALSE(state.daemon("cell-a"));
  transport::CellStatus status;
  status.cell = "cell-a";
  status.state = "running";
  status.sensors = {{"kinect", "streaming"}};
  status.sweeps = 42;
  status.dropped_frames = 3;
  status.boxes = 44;
  status.version = 9;
  status.last_sweep_ns = 123;
  const json report = json::parse(state.on_status(status));
  EXPECT_EQ(report, json({{"type", "status"},
                          {"cell", "cell-a"},
                          {"daemon", true},
                          {"state", "running"},
                          {"reason", ""},
                          {"sensors", json::array({{{"name", "kinect"}, {"state", "streaming"}}})},
                          {"last_sweep_ns", 123},
                          {"sweeps", 42},
                          {"dropped_frames", 3},
                          {"refused_inputs", 0},
                          {"boxes", 44},
                          {"version", 9}}));
  EXPECT_TRUE(state.daemon("cell-a"));

  const json gone = json::parse(state.on_daemon_gone("cell-a"));
  EXPECT_EQ(gone["daemon"], false);
  EXPECT_EQ(gone["sweeps"], 42);
  EXPECT_FALSE(state.daemon("cell-a"));
  const json whole = json::parse(state.state());
  EXPECT_EQ(whole["domain"], 5);
  EXPECT_EQ(whole["cell_filter"], "cell-a");
  EXPECT_EQ(whole["cells"][0]["status"]["daemon"], false);
}

TEST(ViewStateTest, OtherCellsAreIgnoredWhenOneIsFollowed) {
  ViewState state(0, "cell-a");
  transport::CellStatus other;
  other.cell = "cell-b";
  other.state = "running";
  EXPECT_EQ(state.on_status(other), "");
  EXPECT_EQ(state.on_version(Environment("cell-b", 1, 1, {}), {"cell-b", 0, 1, 1, {}, {}, {}}, 0), "");
  EXPECT_TRUE(state.cells().empty());
  EXPECT_EQ(json::parse(state.state())["cells"].size(), 0u);
}

TEST(ViewStateTest, LayersAreForwardedAndTheLatestIsKept) {
  ViewState state(0, "");
  transport::VoxelLayer voxels{"cell-a", 12, 99, 0.02, {{-3, 4, 5, 2}, {0, 0, 1, 7}}};
  const json message = json::parse(state.on_layer(voxels));
  EXPECT_EQ(message["type"], "voxels");
  EXPECT_EQ(message["resolution"], 0.02);
  EXPECT_EQ(message["runs"], json::array({-3, 4, 5, 2, 0, 0, 1, 7}));
  transport::ChangeRegionLayer regions{"cell-a", 13, 100, {{Region{{0, 0, 0}, {1, 2, 3}}, 5, 1}}};
  const json region_message = json::parse(state.on_layer(regions));
  EXPECT_EQ(region_message["regions"][0],
            json({{"min", {0.0, 0.0, 0.0}}, {"max", {1.0, 2.0, 3.0}}, {"appeared", 5}, {"vanished", 1}}));
  ASSERT_EQ(state.layers(transport::Layer::kVoxels).size(), 1u);
  EXPECT_EQ(json::parse(state.layers(transport::Layer::kVoxels)[0])["sweep"], 12);
  voxels.sweep = 14;
  state.on_layer(voxels);
  EXPECT_EQ(json::parse(state.layers(transport::Layer::kVoxels)[0])["sweep"], 14);
}

TEST(ViewStateTest, SensorViewsCarryPoseAndOutline) {
  ViewState state(0, "");
  transport::SensorView camera{"kinect", Eigen::Isometry3d::Identity(), FieldOfView{{{0, 0, 1}}, true, 4.5}};
  camera.X_CS.translation() = Eigen::Vector3d(1, 2, 3);
  camera.X_CS.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const transport::SensorView unknown{"replay", Eigen::Isometry3d::Identity(), std::nullopt};
  const json message =
      json::parse(state.on_layer(transport::SensorLayer{"cell-a", 7, 99, {camera, unknown}}));
  EXPECT_EQ(message["type"], "sensors");
  ASSERT_EQ(message["views"].size(), 2u);
  const json& view = message["views"][0];
  EXPECT_EQ(view["sensor"], "kinect");
  EXPECT_EQ(view["position"], json::array({1.0, 2.0, 3.0}));
  EXPECT_NEAR(view["rotation"][0].get<double>(), std::sqrt(0.5), 1e-12);  // w of 90° about z
  EXPECT_NEAR(view["rotation"][3].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_EQ(view["outline"], json::array({json::array({0.0, 0.0, 1.0})}));
  EXPECT_EQ(view["closed"], true);
  EXPECT_EQ(view["max_range"], 4.5);
  EXPECT_EQ(message["views"][1]["outline"], json::array());
  EXPECT_EQ(message["views"][1]["max_range"], 0.0);
  EXPECT_EQ(state.layers(transport::Layer::kSensors).size(), 1u);
  EXPECT_TRUE(state.layers(transport::Layer::kChangeRegions).empty());
}

TEST(ViewStateTest, RobotShapesCarryPoseKindAndSizes) {
  ViewState state(0, "");
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->vertices = {{0, 0, 0}, {0.123456, 0, 0}, {0, 0.2, 0}};
  mesh->triangles = {{0, 1, 2}};
  Eigen::Isometry3d X_CG = Eigen::Isometry3d::Identity();
  X_CG.translation() = Eigen::Vector3d(1.5, -0.45, 0.5);
  X_CG.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const transport::RobotLayer layer{
      "cell-a",
      4,
      99,
      1.0,
      0.04,
      {{"base_link", false, X_CG, MeshShape{mesh}},
       {"link_2", false, Eigen::Isometry3d::Identity(), CylinderShape{0.05, 0.2}},
       {"link_3", false, Eigen::Isometry3d::Identity(), SphereShape{0.07}},
       {"tool0", true, Eigen::Isometry3d::Identity(), BoxShape{{0.2, 0.15, 0.1}}}}};
  const json message = json::parse(state.on_layer(layer));
  EXPECT_EQ(message["type"], "robot");
  EXPECT_EQ(message["sweep"], 4);
  EXPECT_EQ(message["padding"], 0.04);
  ASSERT_EQ(message["shapes"].size(), 4u);
  const json& base = message["shapes"][0];
  EXPECT_EQ(base["link"], "base_link");
  EXPECT_EQ(base["kind"], "mesh");
  EXPECT_EQ(base["position"], json::array({1.5, -0.45, 0.5}));
  EXPECT_NEAR(base["rotation"][0].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(base["rotation"][3].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_EQ(base["vertices"], json::array({0.0, 0.0, 0.0, 0.1235, 0.0, 0.0, 0.0, 0.2, 0.0}));  // to 0.1 mm
  EXPECT_EQ(base["triangles"], json::array({0, 1, 2}));
  EXPECT_EQ(message["shapes"][1]["kind"], "cylinder");
  EXPECT_EQ(message["shapes"][1]["radius"], 0.05);
  EXPECT_EQ(message["shapes"][1]["half_length"], 0.2);
  EXPECT_EQ(message["shapes"][2]["kind"], "sphere");
  EXPECT_EQ(message["shapes"][2]["radius"], 0.07);
  EXPECT_EQ(message["shapes"][3]["kind"], "box");
  EXPECT_EQ(message["shapes"][3]["carried"], true);
  EXPECT_EQ(message["shapes"][3]["half_extents"], json::array({0.2, 0.15, 0.1}));
  EXPECT_EQ(state.layers(transport::Layer::kRobot).size(), 1u);
}

}  // namespace
}  // namespace cellmap::view
