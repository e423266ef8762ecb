// SPDX-License-Identifier: Apache-2.0
#pragma once
// What moves in the simulated cell while frames are taken: the robot along a production path (with what it
// picks and places) and people walking through. Plain value types; the Simulator renders them.

#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <vector>

#include "cellmap/robot/joint_state.hpp"
#include "cellmap/robot/robot.hpp"

namespace cellmap::sim {

struct Obstacle;

/// A point of the robot's path: the joint vector reached at `time` (seconds from the motion's start).
struct Waypoint final {
  double time = 0.0;
  Eigen::VectorXd q;
  std::string pick;    ///< a box obstacle the tool takes here (it is carried from now on, part of the robot)
  bool place = false;  ///< the carried box is put down here (it becomes an obstacle where it is)
};

/// A robot that never stops: between waypoints every joint moves with a smooth step (zero speed at each
/// waypoint, s = 3u² − 2u³ of the segment's time fraction u); two waypoints with the same q make the robot
/// hold still. With `loop` the path repeats (the last waypoint should equal the first; no pick or place
/// then); without, the robot stays at the last waypoint. The controller reports joint samples
/// `controller_rate` times a second, each stamped `joint_stamp_delay` seconds after the instant it describes
/// (an uncorrected controller latency).
struct Motion final {
  std::vector<Waypoint> waypoints;  ///< times strictly increasing, the first at 0
  bool loop = true;
  double controller_rate = 250.0;  ///< Hz
  double joint_stamp_delay = 0.0;  ///< seconds

  /// The joint vector at time t (any t >= 0; before 0: the first waypoint).
  [[nodiscard]] Eigen::VectorXd q_at(double t) const;
  [[nodiscard]] double duration() const { return waypoints.back().time; }
  /// @throws Error naming the waypoint if times do not increase from 0, a q is not within the robot's
  /// limits, a loop picks or places, a place has nothing carried or a pick carries twice.
  void validate(const Robot& robot) const;
};

/// A person walking through the cell: a cylinder body (radius, standing on the floor at z = floor) with a
/// sphere head on top, `height` tall in all, at the floor point interpolated linearly along `path` at time t;
/// absent before the first point's time and after the last's (arrived and left).
struct Walker final {
  struct Point {
    double time = 0.0;
    Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  };
  std::string name;
  double radius = 0.25;
  double height = 1.75;
  double floor = 0.0;
  std::vector<Point> path;

  /// The body and head obstacles ("<name>_body", "<name>_head") at time t, none when absent.
  [[nodiscard]] std::vector<Obstacle> at(double t) const;
  /// @throws Error naming the walker if sizes are not positive (head radius = 0.6 · radius < height / 2) or
  /// the path has fewer than two points or times that do not increase.
  void validate() const;
};

}  // namespace cellmap::sim
