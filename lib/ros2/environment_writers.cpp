// SPDX-License-Identifier: Apache-2.0
#include "cellmap/ros2/environment_writers.hpp"

#include <vector>

#include "cellmap/ros2/topics.hpp"
#include "cellmap/ros2/type_hash.hpp"
#include "moveit_msgs/msg/CollisionObject.h"
#include "visualization_msgs/msg/MarkerArray.h"

namespace cellmap::ros2 {
namespace {

// The idlc types hold non-const char*; the serializer only reads them.
char* text(const std::string& s) {
  return const_cast<char*>(s.c_str());
}
char* empty_text() {
  static char empty[] = "";
  return empty;
}

template <typename Sequence, typename T>
Sequence sequence_of(std::vector<T>& items) {
  Sequence seq{};
  seq._length = seq._maximum = static_cast<std::uint32_t>(items.size());
  seq._buffer = items.data();
  seq._release = false;
  return seq;
}

std_msgs_msg_dds__Header_ header(std::int64_t stamp_ns, const std::string& frame_id) {
  std_msgs_msg_dds__Header_ h{};
  h.stamp.sec = static_cast<std::int32_t>(stamp_ns / 1'000'000'000);
  h.stamp.nanosec = static_cast<std::uint32_t>(stamp_ns % 1'000'000'000);
  h.frame_id = text(frame_id);
  return h;
}

geometry_msgs_msg_dds__Pose_ pose_of(const Box& box) {
  geometry_msgs_msg_dds__Pose_ pose{};
  pose.position = {box.center.x(), box.center.y(), box.center.z()};
  const Eigen::Quaterniond& q = box.rotation;
  pose.orientation = {q.x(), q.y(), q.z(), q.w()};
  return pose;
}

geometry_msgs_msg_dds__Pose_ identity_pose() {
  geometry_msgs_msg_dds__Pose_ pose{};
  pose.orientation.w = 1.0;
  return pose;
}

// One CollisionObject with its own storage for what its sequences point to.
class CollisionObjectSample final {
 public:
  CollisionObjectSample(const std::string& cell, const Box& box, std::int64_t stamp_ns,
                        const std::string& frame_id, std::uint8_t operation)
      : id_(collision_object_id(cell, box.id, box.space)),
        sizes_{2 * box.half_extents.x(), 2 * box.half_extents.y(), 2 * box.half_extents.z()},
        primitive_poses_{identity_pose()} {
    msg_.header = header(stamp_ns, frame_id);
    msg_.id = text(id_);
    msg_.type.key = msg_.type.db = empty_text();
    msg_.operation = operation;
    if (operation == moveit_msgs_msg_dds__CollisionObject_Constants_REMOVE_) return;
    msg_.pose = pose_of(box);
    shape_msgs_msg_dds__SolidPrimitive_ primitive{};
    primitive.type = shape_msgs_msg_dds__SolidPrimitive_Constants_BOX_;
    primitive.dimensions = sequence_of<dds_sequence_double>(sizes_);
    primitives_.push_back(primitive);
    msg_.primitives = sequence_of<dds_sequence_shape_msgs_msg_dds__SolidPrimitive_>(primitives_);
    msg_.primitive_poses = sequence_of<dds_sequence_geometry_msgs_msg_dds__Pose_>(primitive_poses_);
  }
  CollisionObjectSample(const CollisionObjectSample&) = delete;
  CollisionObjectSample& operator=(const CollisionObjectSample&) = delete;
  [[nodiscard]] const moveit_msgs_msg_dds__CollisionObject_* get() const { return &msg_; }

 private:
  std::string id_;
  std::vector<double> sizes_;
  std::vector<shape_msgs_msg_dds__SolidPrimitive_> primitives_;
  std::vector<geometry_msgs_msg_dds__Pose_> primitive_poses_;
  moveit_msgs_msg_dds__CollisionObject_ msg_{};
};

void write_object(const dds::Writer& writer, const std::string& cell, const Box& box, std::int64_t stamp_ns,
                  const std::string& frame_id, std::uint8_t operation) {
  const CollisionObjectSample sample(cell, box, stamp_ns, frame_id, operation);
  writer.write(sample.get());
}

visualization_msgs_msg_dds__Marker_ blank_marker(const std_msgs_msg_dds__Header_& h, const std::string& ns) {
  visualization_msgs_msg_dds__Marker_ m{};
  m.header = h;
  m.ns = text(ns);
  m.pose = identity_pose();
  m.texture_resource = m.text = m.mesh_resource = empty_text();
  m.texture.header.frame_id = m.texture.format = empty_text();
  m.mesh_file.filename = empty_text();
  return m;
}

visualization_msgs_msg_dds__Marker_ cube(const std_msgs_msg_dds__Header_& h, const std::string& ns,
                                         const Box& box) {
  visualization_msgs_msg_dds__Marker_ m = blank_marker(h, ns);
  m.id = static_cast<std::int32_t>(box.id & 0x7fffffffu);
  m.type = visualization_msgs_msg_dds__Marker_Constants_CUBE_;
  m.action = visualization_msgs_msg_dds__Marker_Constants_ADD_;
  m.pose = pose_of(box);
  m.scale = {2 * box.half_extents.x(), 2 * box.half_extents.y(), 2 * box.half_extents.z()};
  const std::array<double, 3> rgb = box.space == BoxSpace::kUnknown ? kUnknownColour : box_colour(box.id);
  m.color = {float(rgb[0]), float(rgb[1]), float(rgb[2]), marker_alpha(box.space)};
  return m;
}

// Whether `output` carries `box`.
bool carries(const TopicOutput& output, const Box& box) {
  return box.space != BoxSpace::kUnknown || output.unknown_boxes;
}

// KEEP_ALL: a version's burst of boxes must reach MoveIt whole.
dds::Qos collision_object_qos() {
  dds::Qos qos = dds::Qos::make(false, 0);
  qos.user_data(type_hash_user_data("moveit_msgs/msg/CollisionObject"));
  return qos;
}

dds::Qos marker_qos() {
  dds::Qos qos = dds::Qos::make(true, 1);
  qos.user_data(type_hash_user_data("visualization_msgs/msg/MarkerArray"));
  return qos;
}

}  // namespace

std::string collision_object_id(const std::string& cell, std::uint64_t box_id, BoxSpace space) {
  return "cellmap/" + cell + (space == BoxSpace::kUnknown ? "/unknown_" : "/box_") + std::to_string(box_id);
}

std::string marker_namespace(const std::string& cell, BoxSpace space) {
  return space == BoxSpace::kUnknown ? cell + "/unknown" : cell;
}

float marker_alpha(BoxSpace space) {
  return space == BoxSpace::kUnknown ? 0.3f : 0.6f;
}

CollisionObjectWriter::CollisionObjectWriter(const dds::Participant& participant, TopicOutput output)
    : output_(std::move(output)),
      topic_(participant, &moveit_msgs_msg_dds__CollisionObject__desc, dds_topic(output_.topic)),
      writer_(participant, topic_, collision_object_qos()) {}

void CollisionObjectWriter::write(const Environment& after, const EnvironmentDelta& delta) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const Environment before = std::move(current_);
  current_ = after;
  const auto send = [&](const Box& box, std::uint8_t operation) {
    if (carries(output_, box))
      write_object(writer_, after.cell(), box, after.stamp_ns(), output_.frame_id, operation);
  };
  // A box this writer never saw (none before the first write) may have been of either space.
  const auto remove = [&](std::uint64_t id) {
    Box gone;
    gone.id = id;
    if (const Box* known = before.find(id)) {
      gone.space = known->space;
      send(gone, moveit_msgs_msg_dds__CollisionObject_Constants_REMOVE_);
      return;
    }
    for (const BoxSpace space : {BoxSpace::kOccupied, BoxSpace::kUnknown}) {
      gone.space = space;
      send(gone, moveit_msgs_msg_dds__CollisionObject_Constants_REMOVE_);
    }
  };
  for (const Box& box : delta.added) send(box, moveit_msgs_msg_dds__CollisionObject_Constants_ADD_);
  for (const Box& box : delta.modified) {
    // A box whose space changed has another object id: the old object goes.
    const Box* known = before.find(box.id);
    if (known != nullptr && known->space != box.space) remove(box.id);
    send(box, moveit_msgs_msg_dds__CollisionObject_Constants_ADD_);
  }
  for (const std::uint64_t id : delta.removed) remove(id);
}

bool CollisionObjectWriter::resend_if_new_readers() {
  const std::lock_guard<std::mutex> lock(mutex_);
  const std::uint32_t ever = writer_.matched_readers_ever();
  if (ever == readers_seen_) return false;
  readers_seen_ = ever;
  for (const Box& box : current_.boxes()) {
    if (carries(output_, box))
      write_object(writer_, current_.cell(), box, current_.stamp_ns(), output_.frame_id,
                   moveit_msgs_msg_dds__CollisionObject_Constants_ADD_);
  }
  return true;
}

MarkerWriter::MarkerWriter(const dds::Participant& participant, TopicOutput output)
    : output_(std::move(output)),
      topic_(participant, &visualization_msgs_msg_dds__MarkerArray__desc, dds_topic(output_.topic)),
      writer_(participant, topic_, marker_qos()) {}

void MarkerWriter::write(const Environment& env) {
  const std_msgs_msg_dds__Header_ h = header(env.stamp_ns(), output_.frame_id);
  // The namespaces outlive this function's markers: the samples point at their text.
  const std::string namespaces[2] = {marker_namespace(env.cell(), BoxSpace::kOccupied),
                                     marker_namespace(env.cell(), BoxSpace::kUnknown)};
  std::vector<visualization_msgs_msg_dds__Marker_> markers;
  markers.reserve(env.boxes().size() + 2);
  // Unknown boxes' namespace is cleared even when they are not written: an RViz still showing them from an
  // earlier cellmapd loses them.
  for (const std::string& ns : namespaces) {
    visualization_msgs_msg_dds__Marker_ clear = blank_marker(h, ns);
    clear.action = visualization_msgs_msg_dds__Marker_Constants_DELETEALL_;
    markers.push_back(clear);
  }
  for (const Box& box : env.boxes()) {
    if (carries(output_, box))
      markers.push_back(cube(h, namespaces[box.space == BoxSpace::kUnknown ? 1 : 0], box));
  }
  visualization_msgs_msg_dds__MarkerArray_ msg{};
  msg.markers = sequence_of<dds_sequence_visualization_msgs_msg_dds__Marker_>(markers);
  writer_.write(&msg);
}

}  // namespace cellmap::ros2
