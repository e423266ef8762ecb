// SPDX-License-Identifier: Apache-2.0
// ros2_peer (eProsima Fast DDS 2.9 with fastddsgen's types, standing in for a ROS 2 node) against plain
// Cyclone DDS with idlc's types of the same idl/ros2 files: every field arrives exactly, both ways, on
// loopback. What passes here is what two independent vendors agree on: ROS 2's topic and type names, QoS and
// plain CDR, i.e. what a real ROS 2 node (rmw_fastrtps or rmw_cyclonedds) sees of cellmapd.
#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <functional>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cellmap/transport/dds.hpp"
#include "moveit_msgs/msg/CollisionObject.h"
#include "sensor_msgs/msg/JointState.h"
#include "sensor_msgs/msg/LaserScan.h"
#include "sensor_msgs/msg/PointCloud2.h"
#include "support/dds_domains.hpp"
#include "support/test_support.hpp"
#include "transport/child_process.hpp"
#include "transport/loopback.hpp"
#include "visualization_msgs/msg/MarkerArray.h"

namespace cellmap {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;
const auto kPatience = test::kPatience * test::kSanitizerSlowdown;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

/// ros2_peer as a process: commands to its stdin, its JSON lines read by event.
class Peer {
 public:
  explicit Peer(int domain)
      : process_({ROS2_PEER, "--domain", std::to_string(domain)}, test::ChildProcess::Input::from_test) {
    expect("ready");
  }

  /// Sends one command line; with a payload, " bytes=N" and the N bytes after the line.
  void send(const std::string& command, const std::string& payload = {}) {
    process_.write_input(payload.empty() ? command + "\n"
                                         : command + " bytes=" + std::to_string(payload.size()) + "\n");
    process_.write_input(payload);
  }

  /// The next line whose "event" is `event`; lines of other events are kept for later calls. @throws
  /// std::runtime_error on an "error" line, or when no such line comes in time.
  json expect(const std::string& event, std::chrono::milliseconds patience = kPatience) {
    for (auto it = backlog_.begin(); it != backlog_.end(); ++it) {
      if ((*it)["event"] == event) {
        json found = *it;
        backlog_.erase(it);
        return found;
      }
    }
    const auto deadline = std::chrono::steady_clock::now() + patience;
    for (;;) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      const std::optional<std::string> line = process_.read_line(std::max(left, 0ms));
      if (!line) throw std::runtime_error("ros2_peer printed no '" + event + "' line in time");
      json parsed = json::parse(*line);
      if (parsed["event"] == "error") throw std::runtime_error("ros2_peer: " + parsed.dump());
      if (parsed["event"] == event) return parsed;
      backlog_.push_back(std::move(parsed));
    }
  }

  /// Ends its input and returns its exit code (it waits up to 2 s for acknowledgments first).
  int finish() {
    process_.close_input();
    return test::exit_code(process_.wait());
  }

  /// Sends SIGTERM and returns the exit code, or -2 if it did not end within the patience.
  int terminate() {
    process_.signal(SIGTERM);
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while (process_.running() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(10ms);
    if (process_.running()) return -2;
    return test::exit_code(process_.wait());
  }

 private:
  test::ChildProcess process_;
  std::deque<json> backlog_;
};

class Interop : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::use_loopback(); }
};

/// Takes samples from `reader` until `wanted` of them counted or the patience ran out; `check` sees each one
/// (valid only during the call) and says whether it counts. Returns how many counted.
template <typename Sample>
int take(const dds::Reader& reader, int wanted, const std::function<bool(const Sample&)>& check) {
  int count = 0;
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (count < wanted && std::chrono::steady_clock::now() < deadline) {
    const std::size_t taken = reader.take_all([&](const void* sample, const dds_sample_info_t&) {
      if (check(*static_cast<const Sample*>(sample))) ++count;
    });
    if (taken == 0) std::this_thread::sleep_for(5ms);
  }
  return count;
}

/// Has the peer run `command` (with `payload`) again and again until `reader` takes a sample, and checks the
/// first one with `check`. Once matched, a Cyclone DDS 0.10 reader accepts data of a reliable writer only
/// after the writer's first HEARTBEAT, and drops as history everything that heartbeat announces: a sample
/// Fast DDS wrote before its first heartbeat reached Cyclone is lost for good (seen here with 5 MB clouds
/// under load, the first of five). Any ROS 2 node on Fast DDS meets a Cyclone subscriber the same way.
/// Later samples of that writer are reliable.
template <typename Sample>
void publish_until_taken(Peer& peer, const std::string& command, const std::string& payload,
                         const dds::Reader& reader, const std::function<void(const Sample&)>& check) {
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  int taken = 0;
  while (taken == 0) {
    if (std::chrono::steady_clock::now() > deadline) throw std::runtime_error("no sample of: " + command);
    peer.send(command, payload);
    peer.expect("published");
    const auto retry = std::chrono::steady_clock::now() + 500ms;
    while (taken == 0 && std::chrono::steady_clock::now() < retry) {
      reader.take_all([&](const void* sample, const dds_sample_info_t&) {
        if (taken++ == 0) check(*static_cast<const Sample*>(sample));
      });
      std::this_thread::sleep_for(5ms);
    }
  }
}

bool wait_for_writers(const dds::Reader& reader, std::uint32_t count) {
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (reader.matched_writers() < count) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(10ms);
  }
  return true;
}

template <typename T>
void put(std::string& bytes, std::size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof value);
}

std::string little_endian_floats(const std::vector<float>& values) {
  std::string bytes(values.size() * 4, '\0');
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &values[i], sizeof bits);
    for (int b = 0; b < 4; ++b) bytes[4 * i + b] = static_cast<char>(bits >> (8 * b));
  }
  return bytes;
}

// Cyclone's sequences point into storage the test owns (_release false: nothing is freed by Cyclone).
template <typename Sequence, typename T>
Sequence sequence(std::vector<T>& items) {
  Sequence s{};
  s._maximum = s._length = static_cast<std::uint32_t>(items.size());
  s._buffer = items.empty() ? nullptr : items.data();
  s._release = false;
  return s;
}

char* text(const char* value) {
  return const_cast<char*>(value);
}

geometry_msgs_msg_dds__Pose_ pose(double x, double y, double z, double yaw) {
  geometry_msgs_msg_dds__Pose_ p{};
  p.position = {x, y, z};
  p.orientation = {0.0, 0.0, std::sin(yaw / 2), std::cos(yaw / 2)};
  return p;
}

json to_json(const geometry_msgs_msg_dds__Pose_& p) {
  return {{"position", {{"x", p.position.x}, {"y", p.position.y}, {"z", p.position.z}}},
          {"orientation",
           {{"x", p.orientation.x}, {"y", p.orientation.y}, {"z", p.orientation.z}, {"w", p.orientation.w}}}};
}

json header_json(std::int32_t sec, std::uint32_t nanosec, const std::string& frame) {
  return {{"stamp", {{"sec", sec}, {"nanosec", nanosec}}}, {"frame_id", frame}};
}

// --- the peer publishes, Cyclone reads ------------------------------------------------------------------

TEST_F(Interop, CyclonePeerGetsEveryFieldOfCloudScanAndJointState) {
  const dds::Participant participant(test::domain::kPeerPublishes);
  const dds::Topic cloud_topic(participant, &sensor_msgs_msg_dds__PointCloud2__desc,
                               "rt/camera/depth/points");
  const dds::Topic scan_topic(participant, &sensor_msgs_msg_dds__LaserScan__desc, "rt/scan");
  const dds::Topic joints_topic(participant, &sensor_msgs_msg_dds__JointState__desc, "rt/joint_states");
  // ROS 2's default QoS: RELIABLE, VOLATILE, KEEP_LAST 10.
  const dds::Reader clouds(participant, cloud_topic, dds::Qos::make(false, 10));
  const dds::Reader scans(participant, scan_topic, dds::Qos::make(false, 10));
  const dds::Reader joints(participant, joints_topic, dds::Qos::make(false, 10));

  Peer peer(test::domain::kPeerPublishes);
  peer.send("advertise topic=/camera/depth/points type=sensor_msgs/msg/PointCloud2");
  peer.send("advertise topic=/scan type=sensor_msgs/msg/LaserScan");
  peer.send(
      "advertise topic=joint_states type=sensor_msgs/msg/JointState");  // relative: the same /joint_states
  for (const char* topic : {"/camera/depth/points", "/scan", "joint_states"}) {
    peer.send(std::string("wait-match count=1 timeout=30 topic=") + topic);
    EXPECT_EQ(peer.expect("matched")["count"], 1) << topic;
  }
  ASSERT_TRUE(wait_for_writers(clouds, 1) && wait_for_writers(scans, 1) && wait_for_writers(joints, 1));

  // An organized 2x3 cloud of float64 x, y, z at offsets 8, 16, 24 of a 32-byte point (a float32 intensity at
  // 4, bytes 0-3 padding) and 8 bytes of padding after each row; the point at row 1, column 2 is NaN.
  const std::uint32_t point_step = 32;
  const std::uint32_t row_step = 3 * point_step + 8;
  std::string cloud(2 * row_step, '\x5a');  // padding keeps its bytes too
  for (std::uint32_t row = 0; row < 2; ++row) {
    for (std::uint32_t column = 0; column < 3; ++column) {
      const std::size_t at = row * row_step + column * point_step;
      const bool hole = row == 1 && column == 2;
      put(cloud, at + 4, static_cast<float>(row * 3 + column) / 7.0f);
      put(cloud, at + 8, hole ? kNaN : 0.1 * column - 1.0 / 3.0);
      put(cloud, at + 16, hole ? kNaN : -0.2 * row + 1e-9);
      put(cloud, at + 24, hole ? kNaN : 1.25 + row * column);
    }
  }
  publish_until_taken<sensor_msgs_msg_dds__PointCloud2_>(
      peer,
      "pub-cloud topic=/camera/depth/points frame=camera_depth_optical_frame stamp=1700000000123456789 "
      "height=2 width=3 point_step=32 row_step=104 bigendian=0 dense=0 "
      "fields=intensity:4:7:1,x:8:8:1,y:16:8:1,z:24:8:1",
      cloud, clouds, [&](const auto& c) {
        EXPECT_EQ(c.header.stamp.sec, 1700000000);
        EXPECT_EQ(c.header.stamp.nanosec, 123456789u);
        EXPECT_STREQ(c.header.frame_id, "camera_depth_optical_frame");
        EXPECT_EQ(c.height, 2u);
        EXPECT_EQ(c.width, 3u);
        ASSERT_EQ(c.fields._length, 4u);
        const std::vector<std::string> names = {"intensity", "x", "y", "z"};
        const std::vector<std::uint32_t> offsets = {4, 8, 16, 24};
        const std::vector<std::uint8_t> datatypes = {7, 8, 8, 8};
        for (std::uint32_t i = 0; i < 4; ++i) {
          EXPECT_EQ(c.fields._buffer[i].name, names[i]);
          EXPECT_EQ(c.fields._buffer[i].offset, offsets[i]);
          EXPECT_EQ(c.fields._buffer[i].datatype, datatypes[i]);
          EXPECT_EQ(c.fields._buffer[i].count, 1u);
        }
        EXPECT_FALSE(c.is_bigendian);
        EXPECT_EQ(c.point_step, point_step);
        EXPECT_EQ(c.row_step, row_step);
        ASSERT_EQ(c.data._length, cloud.size());
        EXPECT_EQ(std::memcmp(c.data._buffer, cloud.data(), cloud.size()),
                  0);  // NaNs and padding bit for bit
        EXPECT_FALSE(c.is_dense);
      });

  const std::vector<float> ranges = {0.5f,   kInf, -kInf, std::numeric_limits<float>::quiet_NaN(),
                                     29.75f, 1e-3f};
  publish_until_taken<sensor_msgs_msg_dds__LaserScan_>(
      peer,
      "pub-scan topic=/scan frame=laser stamp=1700000001000000000 angle_min=-1.5707964 angle_max=1.5707964 "
      "angle_increment=0.0174533 time_increment=1.5e-05 scan_time=0.1 range_min=0.05 range_max=30",
      little_endian_floats(ranges), scans, [&](const auto& s) {
        EXPECT_EQ(s.header.stamp.sec, 1700000001);
        EXPECT_EQ(s.header.stamp.nanosec, 0u);
        EXPECT_STREQ(s.header.frame_id, "laser");
        EXPECT_EQ(s.angle_min, -1.5707964f);
        EXPECT_EQ(s.angle_max, 1.5707964f);
        EXPECT_EQ(s.angle_increment, 0.0174533f);
        EXPECT_EQ(s.time_increment, 1.5e-05f);
        EXPECT_EQ(s.scan_time, 0.1f);
        EXPECT_EQ(s.range_min, 0.05f);
        EXPECT_EQ(s.range_max, 30.0f);
        ASSERT_EQ(s.ranges._length, ranges.size());
        EXPECT_EQ(std::memcmp(s.ranges._buffer, ranges.data(), ranges.size() * sizeof(float)), 0);
        EXPECT_TRUE(std::isnan(s.ranges._buffer[3]));
        EXPECT_EQ(s.intensities._length, 0u);
      });

  // Three names, four positions: the peer sends what it is told (cellmapd must cope with it).
  publish_until_taken<sensor_msgs_msg_dds__JointState_>(
      peer,
      "pub-joints topic=joint_states stamp=1700000002999999999 frame=base_link names=shoulder,elbow,wrist "
      "positions=1.5,2,-0.25,0.1",
      "", joints, [&](const auto& j) {
        EXPECT_EQ(j.header.stamp.sec, 1700000002);
        EXPECT_EQ(j.header.stamp.nanosec, 999999999u);
        EXPECT_STREQ(j.header.frame_id, "base_link");
        ASSERT_EQ(j.name._length, 3u);
        EXPECT_STREQ(j.name._buffer[0], "shoulder");
        EXPECT_STREQ(j.name._buffer[1], "elbow");
        EXPECT_STREQ(j.name._buffer[2], "wrist");
        ASSERT_EQ(j.position._length, 4u);
        EXPECT_EQ(j.position._buffer[0], 1.5);
        EXPECT_EQ(j.position._buffer[1], 2.0);
        EXPECT_EQ(j.position._buffer[2], -0.25);
        EXPECT_EQ(j.position._buffer[3], 0.1);
        EXPECT_EQ(j.velocity._length, 0u);
        EXPECT_EQ(j.effort._length, 0u);
      });

  // Without stamp= the stamp is the time of the write. The writer is in step now: this one arrives.
  const auto before = std::chrono::system_clock::now();
  peer.send("pub-joints topic=/joint_states names=a positions=0");
  const int count = peer.expect("published")["count"];
  EXPECT_GE(count, 2);  // counted per topic: "joint_states" and "/joint_states" are one
  const int stamped_now = take<sensor_msgs_msg_dds__JointState_>(joints, 1, [&](const auto& j) {
    if (std::strcmp(j.header.frame_id, "base_link") == 0) return false;  // one more of the first kind
    const auto stamp =
        std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
            std::chrono::seconds(j.header.stamp.sec) + std::chrono::nanoseconds(j.header.stamp.nanosec)));
    EXPECT_GE(stamp, before - 1s);
    EXPECT_LE(stamp, std::chrono::system_clock::now() + 1s);
    EXPECT_STREQ(j.header.frame_id, "");
    return true;
  });
  EXPECT_EQ(stamped_now, 1);

  EXPECT_EQ(peer.finish(), 0);
}

// --- Cyclone writes, the peer reads -------------------------------------------------------------------

visualization_msgs_msg_dds__Marker_ empty_marker() {
  visualization_msgs_msg_dds__Marker_ m{};
  m.header.frame_id = text("");
  m.ns = text("");
  m.texture_resource = text("");
  m.texture.header.frame_id = text("");
  m.texture.format = text("");
  m.text = text("");
  m.mesh_resource = text("");
  m.mesh_file.filename = text("");
  return m;
}

// A marker as the peer prints it, every field.
json marker_json(const visualization_msgs_msg_dds__Marker_& m) {
  return {{"header", header_json(m.header.stamp.sec, m.header.stamp.nanosec, m.header.frame_id)},
          {"ns", m.ns},
          {"id", m.id},
          {"type", m.type},
          {"action", m.action},
          {"pose", to_json(m.pose)},
          {"scale", {{"x", m.scale.x}, {"y", m.scale.y}, {"z", m.scale.z}}},
          {"color", {{"r", m.color.r}, {"g", m.color.g}, {"b", m.color.b}, {"a", m.color.a}}},
          {"lifetime", {{"sec", m.lifetime.sec}, {"nanosec", m.lifetime.nanosec}}},
          {"frame_locked", m.frame_locked},
          {"points", json::array()},
          {"colors", json::array()},
          {"texture_resource", ""},
          {"texture", {{"header", header_json(0, 0, "")}, {"format", ""}, {"data", json::array()}}},
          {"uv_coordinates", json::array()},
          {"text", m.text},
          {"mesh_resource", ""},
          {"mesh_file", {{"filename", ""}, {"data", json::array()}}},
          {"mesh_use_embedded_materials", false}};
}

// Two markers as cellmapd sends them: DELETEALL, then a box as a CUBE.
struct MarkerArray {
  MarkerArray(const MarkerArray&) = delete;  // sample points into markers
  explicit MarkerArray(std::int32_t id) {
    markers.push_back(empty_marker());
    markers[0].header.frame_id = text("cell");
    markers[0].action = visualization_msgs_msg_dds__Marker_Constants_DELETEALL_;
    markers.push_back(empty_marker());
    visualization_msgs_msg_dds__Marker_& cube = markers[1];
    cube.header.stamp = {1700000003, 5};
    cube.header.frame_id = text("cell");
    cube.ns = text("cellmap/boxes");
    cube.id = id;
    cube.type = visualization_msgs_msg_dds__Marker_Constants_CUBE_;
    cube.action = visualization_msgs_msg_dds__Marker_Constants_ADD_;
    cube.pose = pose(0.5, -0.25, 1.0 / 3.0, 0.3);
    cube.scale = {0.4, 0.2, 0.1};
    cube.color = {0.1f, 0.5f, 1.0f, 0.8f};
    cube.lifetime = {0, 0};
    cube.text = text("box");
    sample.markers = sequence<dds_sequence_visualization_msgs_msg_dds__Marker_>(markers);
  }
  [[nodiscard]] json expected() const {
    return {{"markers", json::array({marker_json(markers[0]), marker_json(markers[1])})}};
  }
  std::vector<visualization_msgs_msg_dds__Marker_> markers;
  visualization_msgs_msg_dds__MarkerArray_ sample{};
};

TEST_F(Interop, PeerGetsEveryFieldOfCollisionObjectAndMarkerArray) {
  const dds::Participant participant(test::domain::kPeerSubscribes);
  const dds::Topic objects_topic(participant, &moveit_msgs_msg_dds__CollisionObject__desc,
                                 "rt/collision_object");
  const dds::Topic markers_topic(participant, &visualization_msgs_msg_dds__MarkerArray__desc,
                                 "rt/cellmap/markers");
  const dds::Writer objects(participant, objects_topic, dds::Qos::make(false, 10));
  const dds::Writer markers(participant, markers_topic, dds::Qos::make(true, 1));

  Peer peer(test::domain::kPeerSubscribes);
  // MoveIt's planning scene monitor: RELIABLE, VOLATILE, depth 10 (the default); RViz: TRANSIENT_LOCAL.
  peer.send("sub topic=/collision_object type=moveit_msgs/msg/CollisionObject");
  peer.send("sub topic=/cellmap/markers type=visualization_msgs/msg/MarkerArray durability=transient_local");
  peer.send("wait-match topic=/collision_object count=1 timeout=30");
  EXPECT_EQ(peer.expect("matched")["count"], 1);
  peer.send("wait-match topic=/cellmap/markers count=1 timeout=30");
  EXPECT_EQ(peer.expect("matched")["count"], 1);
  ASSERT_TRUE(objects.wait_for_readers(1, kPatience));
  ASSERT_TRUE(markers.wait_for_readers(1, kPatience));

  // One box with a subframe, as cellmapd would add it to MoveIt's world.
  std::vector<double> dimensions = {0.4, 0.2, 0.1};
  std::vector<shape_msgs_msg_dds__SolidPrimitive_> primitives(1);
  primitives[0].type = shape_msgs_msg_dds__SolidPrimitive_Constants_BOX_;
  primitives[0].dimensions = sequence<dds_sequence_double>(dimensions);
  std::vector<geometry_msgs_msg_dds__Pose_> primitive_poses = {pose(0.0, 0.0, 0.05, 0.0)};
  std::vector<char*> subframe_names = {text("top")};
  std::vector<geometry_msgs_msg_dds__Pose_> subframe_poses = {pose(0.0, 0.0, 0.1, -0.7853981633974483)};
  moveit_msgs_msg_dds__CollisionObject_ object{};
  object.header.stamp = {1700000004, 250000000};
  object.header.frame_id = text("cell");
  object.pose = pose(1.0 / 3.0, -2.5e-7, 0.75, 1.2);
  object.id = text("cellmap/box/7");
  object.type.key = text("box");
  object.type.db = text("cellmap");
  object.primitives = sequence<dds_sequence_shape_msgs_msg_dds__SolidPrimitive_>(primitives);
  object.primitive_poses = sequence<dds_sequence_geometry_msgs_msg_dds__Pose_>(primitive_poses);
  object.subframe_names = sequence<dds_sequence_string>(subframe_names);
  object.subframe_poses = sequence<dds_sequence_geometry_msgs_msg_dds__Pose_>(subframe_poses);
  object.operation = moveit_msgs_msg_dds__CollisionObject_Constants_ADD_;
  objects.write(&object);

  const json received = peer.expect("received");
  EXPECT_EQ(received["topic"], "/collision_object");
  EXPECT_EQ(received["type"], "moveit_msgs/msg/CollisionObject");
  const json expected = {{"header", header_json(1700000004, 250000000, "cell")},
                         {"pose", to_json(object.pose)},
                         {"id", "cellmap/box/7"},
                         {"type", {{"key", "box"}, {"db", "cellmap"}}},
                         {"primitives", json::array({json{{"type", 1},
                                                          {"dimensions", json::array({0.4, 0.2, 0.1})},
                                                          {"polygon", json{{"points", json::array()}}}}})},
                         {"primitive_poses", json::array({to_json(primitive_poses[0])})},
                         {"meshes", json::array()},
                         {"mesh_poses", json::array()},
                         {"planes", json::array()},
                         {"plane_poses", json::array()},
                         {"subframe_names", json::array({"top"})},
                         {"subframe_poses", json::array({to_json(subframe_poses[0])})},
                         {"operation", 0}};
  EXPECT_EQ(received["msg"], expected) << received["msg"].dump();

  const MarkerArray array(7);
  markers.write(&array.sample);
  const json marker_message = peer.expect("received");
  EXPECT_EQ(marker_message["topic"], "/cellmap/markers");
  EXPECT_EQ(marker_message["type"], "visualization_msgs/msg/MarkerArray");
  EXPECT_EQ(marker_message["msg"], array.expected()) << marker_message["msg"].dump();

  // SIGTERM while it waits for a command: it leaves DDS and exits cleanly.
  EXPECT_EQ(peer.terminate(), 0);
}

TEST_F(Interop, LateTransientLocalReaderGetsTheLastMarkerArrayAgainAfterLeaving) {
  const dds::Participant participant(test::domain::kPeerLateMarkers);
  const dds::Topic topic(participant, &visualization_msgs_msg_dds__MarkerArray__desc, "rt/cellmap/markers");
  const dds::Writer writer(participant, topic, dds::Qos::make(true, 1));
  Peer peer(test::domain::kPeerLateMarkers);
  // Written before any reader exists: only TRANSIENT_LOCAL brings the last one to a late reader.
  const MarkerArray first(1);
  const MarkerArray second(2);
  writer.write(&first.sample);
  writer.write(&second.sample);

  peer.send("sub topic=/cellmap/markers type=visualization_msgs/msg/MarkerArray durability=transient_local");
  EXPECT_EQ(peer.expect("received")["msg"], second.expected());

  // The reader leaves (a MoveIt or RViz that stops) and comes back: it gets the last one again.
  peer.send("unsub topic=/cellmap/markers");
  peer.expect("unsubscribed");
  const MarkerArray third(3);
  writer.write(&third.sample);
  peer.send("sub topic=/cellmap/markers type=visualization_msgs/msg/MarkerArray durability=transient_local");
  EXPECT_EQ(peer.expect("received")["msg"], third.expected());
  EXPECT_EQ(peer.finish(), 0);
}

// --- a camera's cloud -----------------------------------------------------------------------------------

TEST_F(Interop, BigCloudArrivesWhole) {
  const dds::Participant participant(test::domain::kPeerBigCloud);
  const dds::Topic topic(participant, &sensor_msgs_msg_dds__PointCloud2__desc, "rt/camera/depth/points");
  const dds::Reader reader(participant, topic, dds::Qos::make(false, 10));
  Peer peer(test::domain::kPeerBigCloud);
  peer.send("advertise topic=/camera/depth/points type=sensor_msgs/msg/PointCloud2");
  peer.send("wait-match topic=/camera/depth/points count=1 timeout=30");
  EXPECT_EQ(peer.expect("matched")["count"], 1);
  ASSERT_TRUE(wait_for_writers(reader, 1));

  // 640x480 points of 16 bytes (x, y, z, rgb as float32), ~4.9 MB, every byte distinct from its neighbours.
  const std::uint32_t width = 640;
  const std::uint32_t height = 480;
  std::string data(std::size_t{width} * height * 16, '\0');
  std::uint32_t state = 12345;
  for (char& byte : data) {
    state = state * 1664525u + 1013904223u;
    byte = static_cast<char>(state >> 24);
  }
  const std::string cloud_command =
      "pub-cloud topic=/camera/depth/points frame=camera height=480 width=640 point_step=16 row_step=10240 "
      "bigendian=0 dense=1 fields=x:0:7:1,y:4:7:1,z:8:7:1,rgb:12:7:1";
  // Until the writer is in step (publish_until_taken); these carry stamp 0.000000001, the rest real ones.
  publish_until_taken<sensor_msgs_msg_dds__PointCloud2_>(
      peer, cloud_command + " stamp=1", data, reader, [&](const auto& c) {
        ASSERT_EQ(c.data._length, data.size());
        EXPECT_EQ(std::memcmp(c.data._buffer, data.data(), data.size()), 0);
      });
  const auto warm_up = [](const sensor_msgs_msg_dds__PointCloud2_& c) { return c.header.stamp.sec == 0; };

  const int repeat = 5;
  const auto start = std::chrono::steady_clock::now();
  peer.send(cloud_command + " repeat=" + std::to_string(repeat) + " rate=10", data);
  std::vector<std::uint32_t> nanosecs;
  const int taken = take<sensor_msgs_msg_dds__PointCloud2_>(reader, repeat, [&](const auto& c) {
    if (warm_up(c)) return false;
    EXPECT_EQ(c.width, width);
    EXPECT_EQ(c.height, height);
    EXPECT_TRUE(c.data._length == data.size() && std::memcmp(c.data._buffer, data.data(), data.size()) == 0);
    nanosecs.push_back(c.header.stamp.nanosec);
    return true;
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(taken, repeat);  // reliable: every one of them
  const json summary = peer.expect("published");
  EXPECT_EQ(summary["repeat"], repeat);
  // A fresh stamp for each (repeat=K without stamp=).
  for (std::size_t i = 1; i < nanosecs.size(); ++i) EXPECT_NE(nanosecs[i], nanosecs[i - 1]);
  std::cout << "big cloud: " << taken << " x " << data.size() / 1e6 << " MB in " << seconds << " s at 10 Hz; "
            << "peer: " << summary.dump() << "\n";

  // As fast as it goes: what the loopback carries from Fast DDS to Cyclone.
  const int burst = 10;
  const auto burst_start = std::chrono::steady_clock::now();
  peer.send(cloud_command + " repeat=" + std::to_string(burst), data);
  const int burst_taken = take<sensor_msgs_msg_dds__PointCloud2_>(reader, burst, [&](const auto& c) {
    EXPECT_EQ(c.data._length, data.size());
    return !warm_up(c);
  });
  const double burst_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - burst_start).count();
  EXPECT_GE(burst_taken, 1);  // KEEP_LAST 10 on both sides: a slow reader may lose some, never get a torn one
  std::cout << "big cloud burst: " << burst_taken << " of " << burst << " in " << burst_seconds << " s, "
            << burst_taken * data.size() / 1e6 / burst_seconds
            << " MB/s delivered; peer: " << peer.expect("published").dump() << "\n";
  EXPECT_EQ(peer.finish(), 0);
}

// --- QoS: a BEST_EFFORT publisher (sensor-data QoS, as many camera drivers) ---------------------------

TEST_F(Interop, BestEffortPeerWriterMatchesOnlyBestEffortReaders) {
  const dds::Participant participant(test::domain::kPeerBestEffort);
  const dds::Topic topic(participant, &sensor_msgs_msg_dds__PointCloud2__desc, "rt/camera/depth/points");
  const dds::Reader reliable(participant, topic, dds::Qos::make(false, 10));
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  const dds::Entity best_effort(
      dds::check(dds_create_reader(participant.get(), topic.get(), qos, nullptr), "best-effort reader"));
  dds_delete_qos(qos);

  Peer peer(test::domain::kPeerBestEffort);
  peer.send("advertise topic=/camera/depth/points type=sensor_msgs/msg/PointCloud2 reliability=best_effort");
  peer.send("wait-match topic=/camera/depth/points count=1 timeout=30");
  EXPECT_EQ(peer.expect("matched")["count"], 1);
  // Until the best-effort reader has a sample (each lost one is not repaired, so keep sending).
  int received = 0;
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (received == 0 && std::chrono::steady_clock::now() < deadline) {
    peer.send(
        "pub-cloud topic=/camera/depth/points frame=camera height=1 width=1 point_step=4 row_step=4 "
        "bigendian=0 dense=1 fields=x:0:7:1",
        std::string("\x00\x00\x80\x3f", 4));
    peer.expect("published");
    std::this_thread::sleep_for(50ms);
    void* samples[1] = {nullptr};
    dds_sample_info_t info;
    const dds_return_t n = dds_take(best_effort.get(), samples, &info, 1, 1);
    if (n > 0 && info.valid_data) {
      ++received;
      const auto* cloud = static_cast<const sensor_msgs_msg_dds__PointCloud2_*>(samples[0]);
      EXPECT_EQ(cloud->data._length, 4u);
    }
    if (n > 0) dds_return_loan(best_effort.get(), samples, n);
  }
  EXPECT_EQ(received, 1);
  // The RELIABLE reader (what a default rclcpp subscription asks for) never matched a BEST_EFFORT writer.
  EXPECT_EQ(reliable.matched_writers(), 0u);
  EXPECT_EQ(reliable.take_all([](const void*, const dds_sample_info_t&) {}), 0u);
  peer.send("wait-match topic=/camera/depth/points count=2 timeout=0.2");
  EXPECT_EQ(peer.expect("timeout")["count"], 1);
  EXPECT_EQ(peer.finish(), 0);
}

}  // namespace
}  // namespace cellmap
