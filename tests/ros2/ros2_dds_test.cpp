// SPDX-License-Identifier: Apache-2.0
// The ROS 2 sources and writers against plain Cyclone DDS participants speaking ROS's wire types (idl/ros2),
// in one process on loopback: what a ROS 2 driver sends becomes frames and joint samples, what cellmapd
// writes reaches a MoveIt- or RViz-like reader with every field as sent.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <limits>
#include <mutex>
#include <thread>

#include "cellmap/common/wall_clock.hpp"
#include "cellmap/ros2/environment_writers.hpp"
#include "cellmap/ros2/joint_state_reader.hpp"
#include "cellmap/ros2/sensor_sources.hpp"
#include "cellmap/ros2/topics.hpp"
#include "cellmap/ros2/type_hash.hpp"
#include "moveit_msgs/msg/CollisionObject.h"
#include "sensor_msgs/msg/JointState.h"
#include "sensor_msgs/msg/LaserScan.h"
#include "sensor_msgs/msg/PointCloud2.h"
#include "support/dds_domains.hpp"
#include "support/test_support.hpp"
#include "transport/loopback.hpp"
#include "visualization_msgs/msg/MarkerArray.h"

namespace cellmap::ros2 {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

class Ros2DdsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::use_loopback(); }
};

// Refusal lines as the daemon would count them.
struct Refusals {
  std::mutex mutex;
  std::vector<std::string> lines;
  transport::OnRefused callback() {
    return [this](const std::string& line) {
      const std::lock_guard<std::mutex> lock(mutex);
      lines.push_back(line);
    };
  }
  std::vector<std::string> all() {
    const std::lock_guard<std::mutex> lock(mutex);
    return lines;
  }
};

builtin_interfaces_msg_dds__Time_ stamp_of(std::int64_t ns) {
  return {static_cast<std::int32_t>(ns / 1'000'000'000), static_cast<std::uint32_t>(ns % 1'000'000'000)};
}

char* text(const char* s) {
  return const_cast<char*>(s);
}

// A packed FLOAT32 x, y, z cloud of two points, sent as a ROS 2 driver would.
struct CloudSample {
  std::vector<sensor_msgs_msg_dds__PointField_> fields{
      {text("x"), 0, 7, 1}, {text("y"), 4, 7, 1}, {text("z"), 8, 7, 1}};
  std::vector<float> points{0.5f, -1.0f, 2.0f, 1.0f, 2.0f, 3.0f};
  sensor_msgs_msg_dds__PointCloud2_ msg{};

  CloudSample(const char* frame_id, std::int64_t stamp_ns) {
    msg.header.stamp = stamp_of(stamp_ns);
    msg.header.frame_id = text(frame_id);
    msg.height = 1;
    msg.width = 2;
    msg.fields = {3, 3, fields.data(), false};
    msg.point_step = 12;
    msg.row_step = 24;
    msg.data = {24, 24, reinterpret_cast<std::uint8_t*>(points.data()), false};
  }
};

// Calls next() until a frame comes or `patience` passes.
std::optional<Frame> next_frame(DepthSource& source, std::chrono::seconds patience = test::kPatience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  while (std::chrono::steady_clock::now() < deadline) {
    if (std::optional<Frame> frame = source.next(100ms)) return frame;
  }
  return std::nullopt;
}

// Waits until `refusals` holds `count` lines, driving `source` meanwhile.
void drive_until_refused(DepthSource& source, Refusals& refusals, std::size_t count) {
  const auto deadline = std::chrono::steady_clock::now() + test::kPatience;
  while (refusals.all().size() < count && std::chrono::steady_clock::now() < deadline)
    (void)source.next(50ms);
}

TEST_F(Ros2DdsTest, PointCloud2SourceGivesFramesAndRefusesOtherFramesAndOldStamps) {
  dds::Participant daemon(test::domain::kRos2PointCloud);
  dds::Participant driver(test::domain::kRos2PointCloud);
  Refusals refusals;
  TopicInput input;
  input.topic = "/camera/depth/points";
  input.frame_id = "camera";
  // Wide enough that no pause of a loaded machine between stamping a cloud and reading it refuses it; the old
  // cloud is older still.
  input.max_stamp_skew = std::chrono::minutes(10);
  std::unique_ptr<DepthSource> source = make_point_cloud2_source(daemon, "cam", input, refusals.callback());
  const SourceStatus opened = source->open();
  EXPECT_EQ(opened.state, SourceState::kDisconnected);
  EXPECT_THAT(opened.reason, HasSubstr("no sensor_msgs/msg/PointCloud2 on /camera/depth/points yet"));

  const dds::Topic topic(driver, &sensor_msgs_msg_dds__PointCloud2__desc, "rt/camera/depth/points");
  const dds::Writer writer(driver, topic, dds::Qos::make(false, 10));
  ASSERT_TRUE(writer.wait_for_readers(1, test::kPatience));

  const std::int64_t now = wall_clock_ns();
  const CloudSample cloud("camera", now);
  writer.write(&cloud.msg);
  const std::optional<Frame> frame = next_frame(*source);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->sensor, "cam");
  EXPECT_NEAR(frame->stamp, double(now) * 1e-9, 1e-6);
  ASSERT_EQ(frame->points_S.size(), 2u);
  EXPECT_EQ(frame->points_S[0].x, 0.5f);
  EXPECT_EQ(frame->points_S[1].z, 3.0f);
  EXPECT_EQ(source->status().state, SourceState::kConnected);

  const CloudSample other_frame("camera_link", now);
  writer.write(&other_frame.msg);
  const CloudSample old("camera", now - 3600'000'000'000);  // an hour
  writer.write(&old.msg);
  CloudSample big_endian("camera", now);
  big_endian.msg.is_bigendian = true;
  writer.write(&big_endian.msg);
  drive_until_refused(*source, refusals, 3);
  const std::vector<std::string> lines = refusals.all();
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0],
            "/camera/depth/points (sensor_msgs/msg/PointCloud2): in frame 'camera_link', not 'camera'");
  EXPECT_THAT(lines[1], HasSubstr("s from now"));
  EXPECT_THAT(lines[2], HasSubstr("big-endian clouds are not supported"));
  EXPECT_EQ(source->status().frames, 1u);
}

TEST_F(Ros2DdsTest, PointCloud2SourceSaysWhenItsPublisherFellSilent) {
  dds::Participant daemon(test::domain::kRos2PointCloud);
  dds::Participant driver(test::domain::kRos2PointCloud);
  TopicInput input;
  input.topic = "/lidar/points";
  input.frame_id = "lidar";
  input.frame_timeout = 0.2;
  std::unique_ptr<DepthSource> source = make_point_cloud2_source(daemon, "lidar", input, {});
  (void)source->open();
  const dds::Topic topic(driver, &sensor_msgs_msg_dds__PointCloud2__desc, "rt/lidar/points");
  const dds::Writer writer(driver, topic, dds::Qos::make(false, 10));
  ASSERT_TRUE(writer.wait_for_readers(1, test::kPatience));
  const CloudSample cloud("lidar", wall_clock_ns());
  writer.write(&cloud.msg);
  ASSERT_TRUE(next_frame(*source));
  const auto deadline = std::chrono::steady_clock::now() + test::kPatience;
  while (source->status().state == SourceState::kConnected && std::chrono::steady_clock::now() < deadline)
    (void)source->next(50ms);
  EXPECT_EQ(source->status().state, SourceState::kDisconnected);
  EXPECT_THAT(source->status().reason,
              HasSubstr("no sensor_msgs/msg/PointCloud2 on /lidar/points for 0.2 s (1 publishers matched)"));
}

TEST_F(Ros2DdsTest, LaserScanSourceGivesReturnsBeamsWithoutReturnAndTheFan) {
  dds::Participant daemon(test::domain::kRos2LaserScan);
  dds::Participant driver(test::domain::kRos2LaserScan);
  TopicInput input;
  input.topic = "/scan";
  input.frame_id = "laser";
  std::unique_ptr<DepthSource> source = make_laser_scan_source(daemon, "os32c", input, {});
  (void)source->open();
  const dds::Topic topic(driver, &sensor_msgs_msg_dds__LaserScan__desc, "rt/scan");
  const dds::Writer writer(driver, topic, dds::Qos::make(false, 10));
  ASSERT_TRUE(writer.wait_for_readers(1, test::kPatience));

  std::vector<float> ranges{1.0f, std::numeric_limits<float>::infinity(), 2.0f};
  sensor_msgs_msg_dds__LaserScan_ scan{};
  scan.header.stamp = stamp_of(wall_clock_ns());
  scan.header.frame_id = text("laser");
  scan.angle_min = -1.0f;
  scan.angle_max = 1.0f;
  scan.angle_increment = 1.0f;
  scan.range_min = 0.1f;
  scan.range_max = 5.0f;
  scan.ranges = {3, 3, ranges.data(), false};
  writer.write(&scan);
  const std::optional<Frame> frame = next_frame(*source);
  ASSERT_TRUE(frame);
  ASSERT_EQ(frame->points_S.size(), 2u);
  EXPECT_NEAR(frame->points_S[0].x, std::cos(-1.0), 1e-6);
  EXPECT_NEAR(frame->points_S[1].y, 2.0 * std::sin(1.0), 1e-6);
  ASSERT_EQ(frame->no_return_S.size(), 1u);
  EXPECT_NEAR(frame->no_return_S[0].x, 5.0, 1e-6);
  ASSERT_TRUE(frame->field_of_view);
  EXPECT_EQ(frame->field_of_view->max_range, 5.0);
}

TEST_F(Ros2DdsTest, JointStatesArePutInTheRobotsOrderAndIncompleteOnesRefused) {
  dds::Participant daemon(test::domain::kRos2JointStates);
  dds::Participant controller(test::domain::kRos2JointStates);
  Refusals refusals;
  JointStateReader reader(daemon, "/joint_states", "arm", {"j1", "j2"}, 5s, refusals.callback());
  const dds::Topic topic(controller, &sensor_msgs_msg_dds__JointState__desc, "rt/joint_states");
  const dds::Writer writer(controller, topic, dds::Qos::make(false, 10));
  ASSERT_TRUE(writer.wait_for_readers(1, test::kPatience));

  const std::int64_t now = wall_clock_ns();
  std::vector<char*> names{text("gripper"), text("j2"), text("j1")};
  std::vector<double> positions{0.01, -0.5, 1.25};
  sensor_msgs_msg_dds__JointState_ msg{};
  msg.header.stamp = stamp_of(now);
  msg.header.frame_id = text("");
  msg.name = {3, 3, names.data(), false};
  msg.position = {3, 3, positions.data(), false};
  writer.write(&msg);
  msg.name._length = msg.position._length = 2;  // gripper and j2 only: j1 is missing
  writer.write(&msg);

  std::vector<transport::RobotJoints> samples;
  const auto deadline = std::chrono::steady_clock::now() + test::kPatience;
  while ((samples.empty() || refusals.all().empty()) && std::chrono::steady_clock::now() < deadline) {
    for (transport::RobotJoints& s : reader.take(100ms)) samples.push_back(std::move(s));
  }
  ASSERT_EQ(samples.size(), 1u);
  EXPECT_EQ(samples[0].cell, "arm");
  EXPECT_EQ(samples[0].stamp_ns, now);
  EXPECT_EQ(samples[0].names, (std::vector<std::string>{"j1", "j2"}));
  EXPECT_EQ(samples[0].positions, (std::vector<double>{1.25, -0.5}));
  ASSERT_EQ(refusals.all().size(), 1u);
  EXPECT_EQ(refusals.all()[0], "/joint_states (sensor_msgs/msg/JointState): no position for joint 'j1'");
  EXPECT_EQ(reader.rejected(), 1u);
}

// What a MoveIt reader saw: id and operation of each object, and the sample itself.
struct SeenObject {
  std::string id;
  int operation = -1;
  std::string frame_id;
  std::vector<double> dimensions;
  double position[3] = {};
  double orientation[4] = {};  // x, y, z, w
};

std::vector<SeenObject> take_objects(const dds::Reader& reader, std::size_t count) {
  std::vector<SeenObject> seen;
  const auto deadline = std::chrono::steady_clock::now() + test::kPatience;
  while (seen.size() < count && std::chrono::steady_clock::now() < deadline) {
    reader.take_all([&](const void* sample, const dds_sample_info_t&) {
      const auto& msg = *static_cast<const moveit_msgs_msg_dds__CollisionObject_*>(sample);
      SeenObject o;
      o.id = msg.id;
      o.operation = msg.operation;
      o.frame_id = msg.header.frame_id;
      if (msg.primitives._length == 1) {
        const auto& p = msg.primitives._buffer[0];
        EXPECT_EQ(p.type, 1);  // BOX
        o.dimensions.assign(p.dimensions._buffer, p.dimensions._buffer + p.dimensions._length);
      }
      o.position[0] = msg.pose.position.x;
      o.position[1] = msg.pose.position.y;
      o.position[2] = msg.pose.position.z;
      o.orientation[0] = msg.pose.orientation.x;
      o.orientation[1] = msg.pose.orientation.y;
      o.orientation[2] = msg.pose.orientation.z;
      o.orientation[3] = msg.pose.orientation.w;
      seen.push_back(o);
    });
    std::this_thread::sleep_for(10ms);
  }
  return seen;
}

// The USER_DATA of the one writer matched with `reader`.
std::string matched_writer_user_data(const dds::Reader& reader) {
  dds_instance_handle_t writer = 0;
  if (dds_get_matched_publications(reader.get(), &writer, 1) != 1) return "no writer matched";
  dds_builtintopic_endpoint_t* endpoint = dds_get_matched_publication_data(reader.get(), writer);
  if (endpoint == nullptr) return "no endpoint data";
  void* data = nullptr;
  size_t size = 0;
  std::string text =
      dds_qget_userdata(endpoint->qos, &data, &size) ? std::string(static_cast<char*>(data), size) : "";
  dds_free(data);
  dds_builtintopic_free_endpoint(endpoint);
  return text;
}

Box box(std::uint64_t id, Eigen::Vector3d center, Eigen::Vector3d half_extents,
        Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity()) {
  Box b;
  b.id = id;
  b.center = center;
  b.half_extents = half_extents;
  b.rotation = rotation;
  b.points = 10;
  return b;
}

// MoveIt's planning scene monitor reads /collision_object RELIABLE, VOLATILE, KEEP_LAST 1024.
dds::Qos moveit_qos() {
  return dds::Qos::make(false, 1024);
}

TEST_F(Ros2DdsTest, CollisionObjectsFollowTheVersionsAndAReaderThatJoinsGetsEveryBox) {
  dds::Participant daemon(test::domain::kRos2CollisionObjects);
  dds::Participant move_group(test::domain::kRos2CollisionObjects);
  CollisionObjectWriter writer(daemon, {"/collision_object", "world"});
  const dds::Topic topic(move_group, &moveit_msgs_msg_dds__CollisionObject__desc, "rt/collision_object");
  const dds::Reader first(move_group, topic, moveit_qos());
  const auto joined = [&] {
    const auto deadline = std::chrono::steady_clock::now() + test::kPatience;
    while (!writer.resend_if_new_readers() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(10ms);
  };
  joined();  // nothing to send yet
  // Discovery tells the reader the writer's type hash, as `ros2 topic info -v` shows it.
  EXPECT_EQ(matched_writer_user_data(first), type_hash_user_data("moveit_msgs/msg/CollisionObject"));

  const Environment v0("arm");
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  const Environment v1("arm", 1, 1'700'000'000'500'000'000,
                       {box(1, {1, 2, 3}, {0.1, 0.2, 0.3}), box(2, {0, 0, 1}, {0.5, 0.5, 0.5}, yaw)});
  writer.write(v1, diff(v0, v1));
  std::vector<SeenObject> seen = take_objects(first, 2);
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].id, "cellmap/arm/box_1");
  EXPECT_EQ(seen[0].operation, 0);  // ADD
  EXPECT_EQ(seen[0].frame_id, "world");
  EXPECT_EQ(seen[0].dimensions, (std::vector<double>{0.2, 0.4, 0.6}));
  EXPECT_EQ(seen[0].position[2], 3.0);
  EXPECT_EQ(seen[1].id, "cellmap/arm/box_2");
  EXPECT_DOUBLE_EQ(seen[1].orientation[2], yaw.z());
  EXPECT_DOUBLE_EQ(seen[1].orientation[3], yaw.w());

  const Environment v2("arm", 2, 1'700'000'001'000'000'000,
                       {box(2, {0, 0, 1.5}, {0.5, 0.5, 0.5}, yaw), box(3, {2, 0, 0}, {0.1, 0.1, 0.1})});
  writer.write(v2, diff(v1, v2));
  seen = take_objects(first, 3);
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0].id, "cellmap/arm/box_3");  // added
  EXPECT_EQ(seen[1].id, "cellmap/arm/box_2");  // modified: ADD replaces it in MoveIt
  EXPECT_EQ(seen[1].operation, 0);
  EXPECT_EQ(seen[1].position[2], 1.5);
  EXPECT_EQ(seen[2].id, "cellmap/arm/box_1");
  EXPECT_EQ(seen[2].operation, 1);  // REMOVE

  // A move_group that starts now gets the current boxes, and box 1 is not among them.
  const dds::Reader late(move_group, topic, moveit_qos());
  joined();
  seen = take_objects(late, 2);
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].id, "cellmap/arm/box_2");
  EXPECT_EQ(seen[1].id, "cellmap/arm/box_3");
  EXPECT_EQ(seen[1].operation, 0);
}

TEST_F(Ros2DdsTest, AnRvizThatStartsLaterGetsTheLastMarkerArray) {
  dds::Participant daemon(test::domain::kRos2Markers);
  dds::Participant rviz(test::domain::kRos2Markers);
  MarkerWriter writer(daemon, {"/cellmap/markers", "world"});
  writer.write(Environment("arm", 1, 5, {box(7, {1, 1, 1}, {0.1, 0.1, 0.1})}));
  const Environment v2("arm", 2, 6,
                       {box(7, {1, 1, 1}, {0.1, 0.1, 0.1}), box(9, {2, 0, 0.5}, {0.3, 0.2, 0.1})});
  writer.write(v2);

  const dds::Topic topic(rviz, &visualization_msgs_msg_dds__MarkerArray__desc, "rt/cellmap/markers");
  const dds::Reader reader(rviz, topic, dds::Qos::make(true, 1));
  std::vector<std::vector<visualization_msgs_msg_dds__Marker_>> arrays;
  std::vector<std::string> namespaces;
  const auto deadline = std::chrono::steady_clock::now() + test::kPatience;
  while (arrays.empty() && std::chrono::steady_clock::now() < deadline) {
    reader.take_all([&](const void* sample, const dds_sample_info_t&) {
      const auto& msg = *static_cast<const visualization_msgs_msg_dds__MarkerArray_*>(sample);
      arrays.emplace_back(msg.markers._buffer, msg.markers._buffer + msg.markers._length);
      for (const auto& m : arrays.back()) namespaces.emplace_back(m.ns);
    });
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_EQ(arrays.size(), 1u);  // the last one only (KEEP_LAST 1)
  const auto& markers = arrays[0];
  ASSERT_EQ(markers.size(), 4u);
  EXPECT_EQ(markers[0].action, 3);  // DELETEALL, obstacle boxes' namespace
  EXPECT_EQ(namespaces[0], "arm");
  EXPECT_EQ(markers[1].action, 3);  // DELETEALL, unknown boxes' namespace
  EXPECT_EQ(namespaces[1], "arm/unknown");
  EXPECT_EQ(markers[2].type, 1);  // CUBE
  EXPECT_EQ(markers[2].id, 7);
  EXPECT_EQ(markers[3].id, 9);
  EXPECT_EQ(namespaces[3], "arm");
  EXPECT_DOUBLE_EQ(markers[3].scale.x, 0.6);
  EXPECT_DOUBLE_EQ(markers[3].scale.z, 0.2);
  EXPECT_EQ(markers[3].pose.position.z, 0.5);
  const std::array<double, 3> rgb = box_colour(9);
  EXPECT_FLOAT_EQ(markers[3].color.r, float(rgb[0]));
  EXPECT_FLOAT_EQ(markers[3].color.a, 0.6f);
}

Box unknown_box(std::uint64_t id, Eigen::Vector3d center, Eigen::Vector3d half_extents) {
  Box b = box(id, center, half_extents);
  b.space = BoxSpace::kUnknown;
  return b;
}

TEST_F(Ros2DdsTest, UnknownBoxesAreCollisionObjectsOfTheirOwnUnlessSwitchedOff) {
  dds::Participant daemon(test::domain::kRos2UnknownObjects);
  dds::Participant move_group(test::domain::kRos2UnknownObjects);
  CollisionObjectWriter with_unknown(daemon, {"/collision_object", "world"});
  CollisionObjectWriter obstacles_only(daemon, {"/obstacles_only", "world", false});
  const dds::Topic topic(move_group, &moveit_msgs_msg_dds__CollisionObject__desc, "rt/collision_object");
  const dds::Topic obstacles_topic(move_group, &moveit_msgs_msg_dds__CollisionObject__desc,
                                   "rt/obstacles_only");
  const dds::Reader reader(move_group, topic, moveit_qos());
  const dds::Reader obstacles_reader(move_group, obstacles_topic, moveit_qos());
  for (CollisionObjectWriter* writer : {&with_unknown, &obstacles_only}) {
    const auto deadline = std::chrono::steady_clock::now() + test::kPatience;
    while (!writer->resend_if_new_readers() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(10ms);
  }

  // Version 1: an obstacle and the space behind it nobody has seen (2 × 1 × 1 m).
  const Environment v0("arm");
  const Environment v1("arm", 1, 1'700'000'000'000'000'000,
                       {box(1, {1, 0, 0.5}, {0.1, 0.1, 0.1}), unknown_box(2, {2, 0, 0.5}, {1.0, 0.5, 0.5})});
  // Version 2: the unknown space was seen (its box goes), another obstacle came.
  const Environment v2("arm", 2, 1'700'000'001'000'000'000,
                       {box(1, {1, 0, 0.5}, {0.1, 0.1, 0.1}), box(3, {2, 0, 0.2}, {0.2, 0.2, 0.2})});
  // Version 3: one more obstacle, after which nothing of version 2 can still be on its way.
  const Environment v3("arm", 3, 1'700'000'002'000'000'000,
                       {box(1, {1, 0, 0.5}, {0.1, 0.1, 0.1}), box(3, {2, 0, 0.2}, {0.2, 0.2, 0.2}),
                        box(4, {0, 1, 0.2}, {0.2, 0.2, 0.2})});
  for (CollisionObjectWriter* writer : {&with_unknown, &obstacles_only}) {
    writer->write(v1, diff(v0, v1));
    writer->write(v2, diff(v1, v2));
    writer->write(v3, diff(v2, v3));
  }

  std::vector<SeenObject> seen = take_objects(reader, 5);
  ASSERT_EQ(seen.size(), 5u);
  EXPECT_EQ(seen[0].id, "cellmap/arm/box_1");
  EXPECT_EQ(seen[1].id, "cellmap/arm/unknown_2");
  EXPECT_EQ(seen[1].operation, 0);  // ADD
  EXPECT_EQ(seen[1].dimensions, (std::vector<double>{2.0, 1.0, 1.0}));
  EXPECT_EQ(seen[1].position[0], 2.0);
  EXPECT_EQ(seen[2].id, "cellmap/arm/box_3");
  EXPECT_EQ(seen[3].id, "cellmap/arm/unknown_2");
  EXPECT_EQ(seen[3].operation, 1);  // REMOVE, under the unknown box's id
  EXPECT_EQ(seen[4].id, "cellmap/arm/box_4");

  // Switched off: the obstacles alone, neither the unknown box's ADD nor its REMOVE.
  seen = take_objects(obstacles_reader, 3);
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0].id, "cellmap/arm/box_1");
  EXPECT_EQ(seen[1].id, "cellmap/arm/box_3");
  EXPECT_EQ(seen[2].id, "cellmap/arm/box_4");

  // A box whose space changed is removed under its old id and added under its new one.
  Box now_unknown = box(4, {0, 1, 0.2}, {0.2, 0.2, 0.2});
  now_unknown.space = BoxSpace::kUnknown;
  const Environment v4(
      "arm", 4, 1'700'000'003'000'000'000,
      {box(1, {1, 0, 0.5}, {0.1, 0.1, 0.1}), box(3, {2, 0, 0.2}, {0.2, 0.2, 0.2}), now_unknown});
  with_unknown.write(v4, diff(v3, v4));
  seen = take_objects(reader, 2);
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].id, "cellmap/arm/box_4");
  EXPECT_EQ(seen[0].operation, 1);
  EXPECT_EQ(seen[1].id, "cellmap/arm/unknown_4");
  EXPECT_EQ(seen[1].operation, 0);

  // A move_group that starts now gets the unknown box too.
  const dds::Reader late(move_group, topic, moveit_qos());
  const auto deadline = std::chrono::steady_clock::now() + test::kPatience;
  while (!with_unknown.resend_if_new_readers() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(10ms);
  seen = take_objects(late, 3);
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[2].id, "cellmap/arm/unknown_4");
}

// The markers of the last MarkerArray on `topic` and their namespaces.
struct SeenMarkers {
  std::vector<visualization_msgs_msg_dds__Marker_> markers;
  std::vector<std::string> namespaces;
};
SeenMarkers last_marker_array(const dds::Participant& rviz, const char* topic_name) {
  const dds::Topic topic(rviz, &visualization_msgs_msg_dds__MarkerArray__desc, topic_name);
  const dds::Reader reader(rviz, topic, dds::Qos::make(true, 1));
  SeenMarkers seen;
  bool got = false;
  const auto deadline = std::chrono::steady_clock::now() + test::kPatience;
  while (!got && std::chrono::steady_clock::now() < deadline) {
    reader.take_all([&](const void* sample, const dds_sample_info_t&) {
      const auto& msg = *static_cast<const visualization_msgs_msg_dds__MarkerArray_*>(sample);
      seen.markers.assign(msg.markers._buffer, msg.markers._buffer + msg.markers._length);
      seen.namespaces.clear();
      for (const auto& m : seen.markers) seen.namespaces.emplace_back(m.ns);
      got = true;
    });
    std::this_thread::sleep_for(10ms);
  }
  for (auto& m : seen.markers) m.ns = nullptr;  // the sample's memory is gone; the names were copied
  return seen;
}

TEST_F(Ros2DdsTest, UnknownBoxesAreGreyMarkersInANamespaceOfTheirOwnUnlessSwitchedOff) {
  dds::Participant daemon(test::domain::kRos2UnknownMarkers);
  dds::Participant rviz(test::domain::kRos2UnknownMarkers);
  MarkerWriter with_unknown(daemon, {"/cellmap/markers", "world"});
  MarkerWriter obstacles_only(daemon, {"/obstacles_only", "world", false});
  const Environment env("arm", 1, 5,
                        {box(7, {1, 1, 1}, {0.1, 0.1, 0.1}), unknown_box(8, {2, 0, 0.5}, {1, 0.5, 0.5})});
  with_unknown.write(env);
  obstacles_only.write(env);

  const SeenMarkers all = last_marker_array(rviz, "rt/cellmap/markers");
  ASSERT_EQ(all.markers.size(), 4u);
  EXPECT_EQ(all.namespaces, (std::vector<std::string>{"arm", "arm/unknown", "arm", "arm/unknown"}));
  EXPECT_EQ(all.markers[0].action, 3);  // DELETEALL
  EXPECT_EQ(all.markers[1].action, 3);
  const auto& unknown = all.markers[3];
  EXPECT_EQ(unknown.type, 1);  // CUBE
  EXPECT_EQ(unknown.id, 8);
  EXPECT_DOUBLE_EQ(unknown.scale.x, 2.0);
  EXPECT_DOUBLE_EQ(unknown.pose.position.x, 2.0);
  for (const float c : {unknown.color.r, unknown.color.g, unknown.color.b}) EXPECT_FLOAT_EQ(c, 0.55f);
  EXPECT_FLOAT_EQ(unknown.color.a, 0.3f);
  const std::array<double, 3> rgb = box_colour(7);
  EXPECT_FLOAT_EQ(all.markers[2].color.g, float(rgb[1]));
  EXPECT_FLOAT_EQ(all.markers[2].color.a, 0.6f);

  // Switched off: the unknown namespace is still cleared, and holds nothing.
  const SeenMarkers obstacles = last_marker_array(rviz, "rt/obstacles_only");
  ASSERT_EQ(obstacles.markers.size(), 3u);
  EXPECT_EQ(obstacles.namespaces, (std::vector<std::string>{"arm", "arm/unknown", "arm"}));
  EXPECT_EQ(obstacles.markers[2].id, 7);
}

}  // namespace
}  // namespace cellmap::ros2
