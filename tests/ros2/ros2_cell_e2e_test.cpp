// SPDX-License-Identifier: Apache-2.0
// cellmapd on config/ros2-cell.yaml fed only by a ROS 2 node of another DDS vendor (Fast DDS:
// tests/ros2/peer), all real processes on loopback: the node publishes the depth camera's PointCloud2
// (rendered by cellmap's simulator, exact depths) and reads what MoveIt's planning scene monitor and RViz
// would, while a planner of cellmap's own follows the versions. A box appears in front of the camera and
// leaves again: each change is one version, and MoveIt's topic gets exactly the matching ADD and REMOVE.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <set>

#include "cellmap/sim/simulator.hpp"
#include "daemon/service_e2e.hpp"
#include "ros2/ros2_peer.hpp"
#include "support/dds_domains.hpp"

namespace cellmap {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

const std::string kCell = "ros2-cell";
const std::string kCloudTopic = "/camera/depth/points";

// The box that appears: floating in front of the camera, clear of the table.
sim::Obstacle appearing_box() {
  sim::Obstacle box;
  box.name = "visitor";
  box.shape = BoxShape{Eigen::Vector3d(0.15, 0.15, 0.15)};
  box.X_CO.translation() = Eigen::Vector3d(1.3, 0.4, -0.2);
  return box;
}

// The camera's organized cloud of `scene` in its frame `camera` (the cell frame: identity mount), NaN where a
// pixel has no return, as an RGB-D driver publishes it.
struct RenderedCloud {
  std::uint32_t width = 0, height = 0;
  std::vector<Eigen::Vector3f> points;
};
RenderedCloud render(const sim::Scene& scene) {
  sim::SimOptions options;
  options.noise = false;
  options.render_robot = false;
  const sim::Simulator simulator(scene, options);
  const sim::SimFrame frame = simulator.render(0, Eigen::VectorXd::Zero(3), 0.0, 0, 0);
  const PinholeIntrinsics& k = scene.sensors[0].intrinsics;
  RenderedCloud cloud{std::uint32_t(k.width), std::uint32_t(k.height), {}};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const double z = frame.exact[std::size_t(v) * std::size_t(k.width) + std::size_t(u)];
      if (z <= 0.0) {
        cloud.points.emplace_back(nan, nan, nan);
        continue;
      }
      const Eigen::Vector3d p_S((u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z);
      cloud.points.push_back((frame.frame.X_CS * p_S).cast<float>());
    }
  }
  return cloud;
}

// The camera driver: publishes the current cloud at 5 Hz until destroyed.
class CameraDriver {
 public:
  CameraDriver(test::Ros2Peer& peer, RenderedCloud cloud) : peer_(peer), cloud_(std::move(cloud)) {
    thread_ = std::thread([this] { run(); });
  }
  ~CameraDriver() {
    stop_ = true;
    thread_.join();
  }
  void show(RenderedCloud cloud) {
    const std::lock_guard<std::mutex> lock(mutex_);
    cloud_ = std::move(cloud);
  }

 private:
  void run() {
    while (!stop_) {
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        peer_.publish_cloud(kCloudTopic, "camera", cloud_.width, cloud_.height, cloud_.points);
      }
      std::this_thread::sleep_for(200ms);
    }
  }
  test::Ros2Peer& peer_;
  std::mutex mutex_;
  RenderedCloud cloud_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// The collision objects MoveIt's topic delivered from event `from` on: id and operation.
std::vector<std::pair<std::string, int>> objects(const test::Ros2Peer& peer, std::size_t from) {
  std::vector<std::pair<std::string, int>> out;
  for (const json& msg : peer.received("/collision_object", from))
    out.emplace_back(msg["id"].get<std::string>(), msg["operation"].get<int>());
  return out;
}

// Obstacle boxes are cellmap/<cell>/box_<id>, unknown boxes (space the camera cannot see)
// cellmap/<cell>/unknown_<id>.
std::string object_id(const Box& box) {
  return "cellmap/" + kCell + (box.space == BoxSpace::kUnknown ? "/unknown_" : "/box_") +
         std::to_string(box.id);
}

// The CollisionObject MoveIt got for `box` matches it: one BOX primitive of its full sizes at its pose.
void expect_matches(const json& msg, const Box& box) {
  EXPECT_EQ(msg["id"], object_id(box));
  EXPECT_EQ(msg["header"]["frame_id"], "world");
  ASSERT_EQ(msg["primitives"].size(), 1u);
  EXPECT_EQ(msg["primitives"][0]["type"], 1);
  const json& dims = msg["primitives"][0]["dimensions"];
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(dims[i].get<double>(), 2 * box.half_extents[i]);
  const json& position = msg["pose"]["position"];
  EXPECT_DOUBLE_EQ(position["x"].get<double>(), box.center.x());
  EXPECT_DOUBLE_EQ(position["y"].get<double>(), box.center.y());
  EXPECT_DOUBLE_EQ(position["z"].get<double>(), box.center.z());
  EXPECT_DOUBLE_EQ(msg["pose"]["orientation"]["w"].get<double>(), box.rotation.w());
}

// The objects the peer received from `from` on, as MoveIt's world would hold them: id → the last ADD.
std::map<std::string, json> world_of(const test::Ros2Peer& peer, std::size_t from) {
  std::map<std::string, json> world;
  for (const json& msg : peer.received("/collision_object", from)) {
    if (msg["operation"] == 0) world[msg["id"]] = msg;
    if (msg["operation"] == 1) world.erase(msg["id"].get<std::string>());
  }
  return world;
}

TEST(Ros2CellE2eTest, ABoxInFrontOfTheCameraIsOneVersionAndOneCollisionObject) {
  test::use_loopback();
  const int domain = test::domain::kRos2Cell;
  const test::TempDir dir;
  const std::filesystem::path config = dir.path() / "ros2-cell.yaml";
  std::ifstream shipped(CELLMAP_SOURCE_DIR "/config/ros2-cell.yaml");
  std::ofstream(config) << shipped.rdbuf() << "\nstatus_period: 0.5\n";

  test::Ros2Peer peer(domain);
  peer.subscribe("/collision_object", "moveit_msgs/msg/CollisionObject", false, 1024);
  peer.subscribe("/cellmap/markers", "visualization_msgs/msg/MarkerArray", true, 1);
  const sim::Scene scene = sim::load_scene(CELLMAP_SOURCE_DIR "/tests/ros2/ros2_cell_scene.yaml");
  sim::Scene with_box = scene;
  with_box.obstacles.push_back(appearing_box());
  CameraDriver camera(peer, render(scene));

  const test::ChildProcess daemon({CELLMAPD, "--config", config.string(), "--domain", std::to_string(domain),
                                   "--state-dir", (dir.path() / "state").string()});
  const dds::Participant participant(static_cast<std::uint32_t>(domain));
  transport::EnvironmentSubscriber planner(participant, kCell);
  transport::StatusReader status(participant);

  // The first version: every box is one ADD on MoveIt's topic.
  const Environment first = test::settled(planner, status, kCell, test::kLongQuietSweeps);
  ASSERT_FALSE(first.boxes().empty());
  // A fixed camera cannot see behind the table and the objects: that space arrives as unknown boxes, which
  // MoveIt gets as objects of their own (on by default: it must not plan through them).
  const auto unknown_boxes = std::count_if(first.boxes().begin(), first.boxes().end(),
                                           [](const Box& box) { return box.space == BoxSpace::kUnknown; });
  EXPECT_GT(unknown_boxes, 0);
  ASSERT_TRUE(peer.wait_until([&] { return world_of(peer, 0).size() == first.boxes().size(); }));
  for (const Box& box : first.boxes()) {
    const std::map<std::string, json> world = world_of(peer, 0);
    ASSERT_EQ(world.count(object_id(box)), 1u) << box.id;
    expect_matches(world.at(object_id(box)), box);
  }

  // The box appears: one version adding one box that holds it, one ADD.
  std::size_t mark = peer.event_count();
  camera.show(render(with_box));
  const Eigen::Vector3d visitor_front(1.15, 0.4, -0.2);
  ASSERT_TRUE(test::wait_until_boxed(planner, visitor_front));
  const Environment arrived = test::settled(planner, status, kCell);
  EXPECT_EQ(arrived.version(), first.version() + 1);
  const EnvironmentDelta arrival = diff(first, arrived);
  ASSERT_EQ(arrival.added.size(), 1u);
  EXPECT_TRUE(arrival.modified.empty());
  EXPECT_TRUE(arrival.removed.empty());
  const Box visitor = arrival.added[0];
  EXPECT_TRUE(visitor.contains(visitor_front, 0.02));
  ASSERT_TRUE(peer.wait_until([&] { return !objects(peer, mark).empty(); }));
  std::this_thread::sleep_for(1s);  // nothing more may come
  ASSERT_EQ(objects(peer, mark), (std::vector<std::pair<std::string, int>>{{object_id(visitor), 0}}));
  expect_matches(peer.received("/collision_object", mark)[0], visitor);

  // It leaves: one version removing it, one REMOVE.
  mark = peer.event_count();
  camera.show(render(scene));
  ASSERT_TRUE(planner.wait_for_version(arrived.version() + 1, test::kDaemonPatience));
  const Environment left = test::settled(planner, status, kCell);
  EXPECT_EQ(left.version(), arrived.version() + 1);
  EXPECT_EQ(diff(arrived, left).removed, std::vector<std::uint64_t>{visitor.id});
  ASSERT_TRUE(peer.wait_until([&] { return !objects(peer, mark).empty(); }));
  std::this_thread::sleep_for(1s);
  EXPECT_EQ(objects(peer, mark), (std::vector<std::pair<std::string, int>>{{object_id(visitor), 1}}));

  // A move_group that starts now gets every current box, and not the one that left.
  peer.command("unsub topic=/collision_object");
  mark = peer.event_count();
  peer.subscribe("/collision_object", "moveit_msgs/msg/CollisionObject", false, 1024);
  ASSERT_TRUE(peer.wait_until([&] { return world_of(peer, mark).size() == left.boxes().size(); }));
  std::set<std::string> expected;
  for (const Box& box : left.boxes()) expected.insert(object_id(box));
  std::set<std::string> got;
  for (const auto& [id, msg] : world_of(peer, mark)) got.insert(id);
  EXPECT_EQ(got, expected);

  // RViz's last MarkerArray: DELETEALL in the obstacles' and the unknown space's namespaces, then a cube per
  // box of the current version: obstacles in their own hues, unknown space grey in its own namespace.
  ASSERT_TRUE(peer.wait_until([&] {
    const std::vector<json> arrays = peer.received("/cellmap/markers");
    return !arrays.empty() && arrays.back()["markers"].size() == left.boxes().size() + 2;
  }));
  const json markers = peer.received("/cellmap/markers").back()["markers"];
  EXPECT_EQ(markers[0]["action"], 3);
  EXPECT_EQ(markers[0]["ns"], kCell);
  EXPECT_EQ(markers[1]["action"], 3);
  EXPECT_EQ(markers[1]["ns"], kCell + "/unknown");
  int grey_markers = 0;
  for (std::size_t i = 0; i < left.boxes().size(); ++i) {
    const Box& box = left.boxes()[i];
    const json& marker = markers[i + 2];
    EXPECT_EQ(marker["type"], 1);
    EXPECT_EQ(marker["id"], box.id);
    const bool unknown = box.space == BoxSpace::kUnknown;
    EXPECT_EQ(marker["ns"], unknown ? kCell + "/unknown" : kCell);
    const std::array<double, 3> rgb = unknown ? kUnknownColour : box_colour(box.id);
    EXPECT_FLOAT_EQ(marker["color"]["r"].get<float>(), float(rgb[0])) << box.id;
    EXPECT_FLOAT_EQ(marker["color"]["g"].get<float>(), float(rgb[1])) << box.id;
    EXPECT_FLOAT_EQ(marker["color"]["b"].get<float>(), float(rgb[2])) << box.id;
    EXPECT_FLOAT_EQ(marker["color"]["a"].get<float>(), unknown ? 0.3f : 0.6f) << box.id;
    grey_markers += unknown ? 1 : 0;
  }
  EXPECT_GT(grey_markers, 0);
}

}  // namespace
}  // namespace cellmap
