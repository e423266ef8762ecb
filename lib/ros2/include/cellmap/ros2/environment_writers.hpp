// SPDX-License-Identifier: Apache-2.0
#pragma once
// The environment for ROS 2 nodes: MoveIt 2's planning scene monitor (moveit_msgs/msg/CollisionObject on
// /collision_object) and RViz (visualization_msgs/msg/MarkerArray on /cellmap/markers), straight over DDS.
// Obstacle boxes and unknown boxes (space no sensor has observed) go out as objects of their own, with ids
// and marker namespaces of their own, so that a ROS node can tell them apart and each can be switched off.

#include <cstdint>
#include <mutex>
#include <string>

#include "cellmap/environment/environment.hpp"
#include "cellmap/transport/dds.hpp"

namespace cellmap::ros2 {

/// Where an output goes and in which frame its poses are (the cell frame C under the name the ROS side
/// knows it by, e.g. MoveIt's planning frame "world").
struct TopicOutput final {
  std::string topic;
  std::string frame_id = "world";
  /// Whether unknown boxes are written too. On by default: a planner that is not told about space nobody has
  /// looked at plans through it.
  bool unknown_boxes = true;
};

/// The MoveIt object id of box `box_id` of `cell`: "cellmap/<cell>/box_<id>" for an obstacle box,
/// "cellmap/<cell>/unknown_<id>" for an unknown box.
[[nodiscard]] std::string collision_object_id(const std::string& cell, std::uint64_t box_id,
                                              BoxSpace space = BoxSpace::kOccupied);

/// The RViz marker namespace of `cell`'s boxes of `space`: "<cell>" for obstacle boxes, "<cell>/unknown"
/// for unknown boxes (RViz lists namespaces with a tick box each, so either can be hidden there too).
[[nodiscard]] std::string marker_namespace(const std::string& cell, BoxSpace space);

/// The alpha of a marker: obstacle boxes 0.6; unknown boxes, large and holding what is unseen, 0.3.
[[nodiscard]] float marker_alpha(BoxSpace space);

/// One moveit_msgs/msg/CollisionObject per box: one BOX primitive (its full sizes) at the box's pose
/// (`pose`; primitive_poses holds the identity), id from collision_object_id. A version's added and modified
/// boxes are sent as ADD (MoveIt replaces an object it has under that id), its removed ones as REMOVE (under
/// the id of the space the box had). Unknown boxes only if the output's `unknown_boxes`.
/// MoveIt's monitor reads /collision_object RELIABLE, VOLATILE, KEEP_LAST 1024, so a writer's history helps
/// no late joiner: whenever a reader matches that did not before (a move_group that started or restarted),
/// every current box is sent again as ADD, and objects it holds from an earlier cellmapd are replaced; boxes
/// removed while it was away are not in the world it starts with. Writes RELIABLE, VOLATILE, KEEP_ALL.
/// Thread-safe: write() and resend_if_new_readers() may run on different threads and never interleave.
class CollisionObjectWriter final {
 public:
  /// `participant` must outlive the writer. @throws Error if the topic name is not a ROS 2 one or the writer
  /// cannot be created.
  CollisionObjectWriter(const dds::Participant& participant, TopicOutput output);
  /// Sends what turned `before` into `after` (the version just published) and keeps `after` for readers
  /// that join later. @throws Error if a write fails.
  void write(const Environment& after, const EnvironmentDelta& delta);
  /// Sends every box of the last written environment as ADD if a reader matched since the last call (or
  /// since construction); true when it did. @throws Error if a write fails.
  bool resend_if_new_readers();
  /// How many readers (move_groups) are matched now.
  [[nodiscard]] std::uint32_t readers() const { return writer_.matched_readers(); }

 private:
  void send_all();
  TopicOutput output_;
  dds::Topic topic_;
  dds::Writer writer_;
  std::mutex mutex_;
  Environment current_;
  std::uint32_t readers_seen_ = 0;
};

/// The boxes for RViz: one visualization_msgs/msg/MarkerArray per version, a DELETEALL marker per namespace
/// first (a resync from scratch, so boxes removed are gone from the display, whether a DELETEALL clears the
/// display or its namespace only) and then one CUBE per box (namespace marker_namespace, id the box id's low
/// 31 bits, the colour the view gives the box, kUnknownColour for unknown boxes, alpha marker_alpha); unknown
/// boxes only if the output's `unknown_boxes`. Written RELIABLE,
/// TRANSIENT_LOCAL, KEEP_LAST 1: an RViz that starts later (durability "Transient Local") shows the cell at
/// once. Thread-safe as Cyclone's writes are.
class MarkerWriter final {
 public:
  /// `participant` must outlive the writer. @throws Error as CollisionObjectWriter's.
  MarkerWriter(const dds::Participant& participant, TopicOutput output);
  /// @throws Error if the write fails.
  void write(const Environment& env);

 private:
  TopicOutput output_;
  dds::Topic topic_;
  dds::Writer writer_;
};

}  // namespace cellmap::ros2
