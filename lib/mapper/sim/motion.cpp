// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/motion.hpp"

#include <algorithm>
#include <cmath>

#include "cellmap/common/error.hpp"
#include "cellmap/sim/scene.hpp"

namespace cellmap::sim {
namespace {

double smooth_step(double u) {
  return u * u * (3.0 - 2.0 * u);
}

}  // namespace

Eigen::VectorXd Motion::q_at(double t) const {
  if (loop && duration() > 0) t = std::fmod(std::max(t, 0.0), duration());
  if (t <= waypoints.front().time) return waypoints.front().q;
  if (t >= waypoints.back().time) return waypoints.back().q;
  const auto next = std::upper_bound(waypoints.begin(), waypoints.end(), t,
                                     [](double time, const Waypoint& w) { return time < w.time; });
  const Waypoint& a = *(next - 1);
  const Waypoint& b = *next;
  const double s = smooth_step((t - a.time) / (b.time - a.time));
  return (1.0 - s) * a.q + s * b.q;
}

void Motion::validate(const Robot& robot) const {
  if (waypoints.size() < 2) throw Error("motion: needs at least two waypoints");
  if (!(controller_rate > 0) || !std::isfinite(controller_rate))
    throw Error("motion: controller_rate must be > 0");
  if (!std::isfinite(joint_stamp_delay)) throw Error("motion: joint_stamp_delay must be finite");
  bool carrying = false;
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    const Waypoint& w = waypoints[i];
    const std::string what = "motion.waypoints[" + std::to_string(i) + "]";
    if (i == 0 && w.time != 0.0) throw Error(what + ".time: the first waypoint is at time 0");
    if (i > 0 && !(w.time > waypoints[i - 1].time)) throw Error(what + ".time: times must increase");
    if (!robot.within_limits(w.q))
      throw Error(what + ".q: outside the robot's joint limits or of the wrong size");
    if (loop && (!w.pick.empty() || w.place)) throw Error(what + ": a looping motion cannot pick or place");
    if (!w.pick.empty() && w.place) throw Error(what + ": pick and place at one waypoint");
    if (!w.pick.empty() && carrying) throw Error(what + ".pick: the tool already carries a box");
    if (w.place && !carrying) throw Error(what + ".place: the tool carries nothing");
    carrying = (carrying || !w.pick.empty()) && !w.place;
  }
}

std::vector<Obstacle> Walker::at(double t) const {
  if (path.empty() || t < path.front().time || t > path.back().time) return {};
  auto next = std::lower_bound(path.begin(), path.end(), t,
                               [](const Point& p, double time) { return p.time < time; });
  Eigen::Vector2d xy = next->xy;
  if (next != path.begin() && next->time != t) {
    const Point& a = *(next - 1);
    const double u = (t - a.time) / (next->time - a.time);
    xy = (1.0 - u) * a.xy + u * next->xy;
  }
  const double head = 0.6 * radius;
  const double body = height - 2.0 * head;
  Obstacle torso{name + "_body", CylinderShape{radius, body / 2.0}, Eigen::Isometry3d::Identity()};
  torso.X_CO.translation() = Eigen::Vector3d(xy.x(), xy.y(), floor + body / 2.0);
  Obstacle skull{name + "_head", SphereShape{head}, Eigen::Isometry3d::Identity()};
  skull.X_CO.translation() = Eigen::Vector3d(xy.x(), xy.y(), floor + body + head);
  return {torso, skull};
}

void Walker::validate() const {
  const std::string what = "walker '" + name + "'";
  if (name.empty()) throw Error("walker: name must not be empty");
  if (!(radius > 0) || !(height > 1.2 * radius) || !std::isfinite(height) || !std::isfinite(floor)) {
    throw Error(what + ": radius must be > 0 and height > 1.2 · radius");
  }
  if (path.size() < 2) throw Error(what + ": path needs at least two points");
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (!path[i].xy.allFinite() || !std::isfinite(path[i].time)) throw Error(what + ": path must be finite");
    if (i > 0 && !(path[i].time > path[i - 1].time)) throw Error(what + ": path times must increase");
  }
}

}  // namespace cellmap::sim
