// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/ray_cast.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "mesh_bvh.hpp"

namespace cellmap::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kParallel = 1e-12;  // a direction component below this counts as parallel to the slab

// Where the ray o + t·d lies between the planes x = lo and x = hi along one axis: [t0, t1], or empty.
bool slab(double o, double d, double lo, double hi, double& t0, double& t1) {
  if (std::abs(d) < kParallel) {
    if (o < lo || o > hi) return false;
    t0 = -kInf, t1 = kInf;
    return true;
  }
  const double a = (lo - o) / d, b = (hi - o) / d;
  t0 = std::min(a, b), t1 = std::max(a, b);
  return true;
}

// Roots of a·t² + b·t + c = 0 with a > 0, as [t0, t1]; false if none. Uses the cancellation-free form.
bool quadratic(double a, double b, double c, double& t0, double& t1) {
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return false;
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  if (q == 0) {  // b = 0 and c = 0: double root at 0
    t0 = t1 = 0;
    return true;
  }
  t0 = q / a, t1 = c / q;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

// The first t >= 0 inside [t0, t1], if the interval reaches t >= 0.
std::optional<double> entry(double t0, double t1) {
  if (t0 > t1 || t1 < 0) return std::nullopt;
  return std::max(t0, 0.0);
}

}  // namespace

std::optional<double> intersect(const BoxShape& box, const Eigen::Vector3d& o_O, const Eigen::Vector3d& d_O) {
  double t0 = -kInf, t1 = kInf;
  for (int i = 0; i < 3; ++i) {
    double a, b;
    if (!slab(o_O[i], d_O[i], -box.half_extents[i], box.half_extents[i], a, b)) return std::nullopt;
    t0 = std::max(t0, a), t1 = std::min(t1, b);
  }
  return entry(t0, t1);
}

std::optional<double> intersect(const CylinderShape& cylinder, const Eigen::Vector3d& o_O,
                                const Eigen::Vector3d& d_O) {
  // The solid is the infinite cylinder x² + y² <= r² intersected with the slab |z| <= half_length.
  double t0 = -kInf, t1 = kInf;
  const double a = d_O.x() * d_O.x() + d_O.y() * d_O.y();
  const double c = o_O.x() * o_O.x() + o_O.y() * o_O.y() - cylinder.radius * cylinder.radius;
  if (a < kParallel) {
    if (c > 0) return std::nullopt;  // parallel to the axis, outside the radius
  } else {
    const double b = 2 * (o_O.x() * d_O.x() + o_O.y() * d_O.y());
    if (!quadratic(a, b, c, t0, t1)) return std::nullopt;
  }
  double z0, z1;
  if (!slab(o_O.z(), d_O.z(), -cylinder.half_length, cylinder.half_length, z0, z1)) return std::nullopt;
  return entry(std::max(t0, z0), std::min(t1, z1));
}

std::optional<double> intersect(const SphereShape& sphere, const Eigen::Vector3d& o_O,
                                const Eigen::Vector3d& d_O) {
  double t0, t1;
  if (!quadratic(d_O.squaredNorm(), 2 * o_O.dot(d_O), o_O.squaredNorm() - sphere.radius * sphere.radius, t0,
                 t1)) {
    return std::nullopt;
  }
  return entry(t0, t1);
}

RobotSolids::RobotSolids(Robot robot) : robot_(std::move(robot)) {
  std::map<const TriangleMesh*, std::shared_ptr<const MeshBvh>> built;  // links sharing a mesh share its tree
  for (const LinkShape& shape : robot_.shapes()) {
    std::shared_ptr<const MeshBvh> bvh;
    if (const auto* mesh = std::get_if<MeshShape>(&shape.geometry)) {
      auto& tree = built[mesh->mesh.get()];
      if (!tree) tree = std::make_shared<const MeshBvh>(*mesh->mesh);
      bvh = tree;
    }
    meshes_.push_back(std::move(bvh));
  }
}

RobotSolids::~RobotSolids() = default;
RobotSolids::RobotSolids(RobotSolids&&) noexcept = default;
RobotSolids& RobotSolids::operator=(RobotSolids&&) noexcept = default;

SceneCaster::SceneCaster(const std::vector<Obstacle>& obstacles) {
  add_obstacles(obstacles);
}

SceneCaster::SceneCaster(const std::vector<Obstacle>& obstacles, const RobotSolids& robot,
                         const JointState& state) {
  add_obstacles(obstacles);
  const std::vector<Eigen::Isometry3d> X_CL = robot.robot().link_poses(state.q);
  const std::vector<LinkShape>& shapes = robot.robot().shapes();
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const Eigen::Isometry3d X_CG =
        X_CL[static_cast<std::size_t>(robot.robot().shape_links()[i])] * shapes[i].X_LG;
    add_robot_shape(shapes[i].geometry, robot.meshes_[i].get(), X_CG);
  }
  if (state.payload)
    add_robot_shape(BoxShape{state.payload->half_extents}, nullptr, X_CL.back() * state.payload->X_EB);
}

void SceneCaster::add_obstacles(const std::vector<Obstacle>& obstacles) {
  entries_.reserve(obstacles.size());
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const Obstacle& o = obstacles[i];
    entries_.push_back(Entry{static_cast<int>(i), o, o.shape, nullptr, o.X_CO.linear().transpose(),
                             o.X_CO.translation(), o.X_CO.translation(), o.bounding_radius()});
  }
}

void SceneCaster::add_robot_shape(const LinkGeometry& geometry, const MeshBvh* mesh,
                                  const Eigen::Isometry3d& X_CG) {
  Entry entry{RayHit::kRobot,     std::nullopt,       BoxShape{}, mesh, X_CG.linear().transpose(),
              X_CG.translation(), X_CG.translation(), 0.0};
  if (mesh) {
    const Region& bounds = mesh->bounds();
    entry.center_C = X_CG * (0.5 * (bounds.min + bounds.max));
    entry.bounding_radius = 0.5 * (bounds.max - bounds.min).norm();
  } else {
    std::visit(
        [&](const auto& shape) {
          using T = std::decay_t<decltype(shape)>;
          if constexpr (!std::is_same_v<T, MeshShape>) {
            entry.shape = shape;
            entry.bounding_radius = Obstacle{"", shape, X_CG}.bounding_radius();
          }
        },
        geometry);
  }
  entries_.push_back(std::move(entry));
}

std::vector<SceneCaster::Candidate> SceneCaster::candidates(const Eigen::Vector3d& apex_C,
                                                            const Eigen::Vector3d& axis_C,
                                                            double half_angle) const {
  std::vector<Candidate> out;
  for (int i = 0; i < size(); ++i) {
    const Entry& e = entries_[static_cast<std::size_t>(i)];
    const Eigen::Vector3d v = e.center_C - apex_C;
    const double distance = v.norm();
    bool keep = half_angle >= M_PI / 2 || distance <= e.bounding_radius;
    if (!keep) {
      // The sphere is seen under a half angle asin(R/distance) about its centre direction.
      const double angle = std::acos(std::clamp(v.dot(axis_C) / distance, -1.0, 1.0));
      keep = angle - std::asin(e.bounding_radius / distance) <= half_angle;
    }
    if (!keep) continue;
    // Obstacles: their exact distance; robot shapes: the distance to their bounding sphere (a lower bound).
    const double min_t = e.obstacle ? e.obstacle->signed_distance(apex_C) : distance - e.bounding_radius;
    out.push_back(Candidate{i, std::max(0.0, min_t)});
  }
  // Nearest first: once a hit is found, farther obstacles (e.g. the floor under the table) are never tested.
  std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) {
    return a.min_t < b.min_t || (a.min_t == b.min_t && a.obstacle < b.obstacle);
  });
  return out;
}

std::optional<double> SceneCaster::hit(const Entry& e, const Eigen::Vector3d& o_C, const Eigen::Vector3d& d_C,
                                       double t_max) const {
  const Eigen::Vector3d o_O = e.R_OC * (o_C - e.p_CO);
  const Eigen::Vector3d d_O = e.R_OC * d_C;
  if (e.mesh) return e.mesh->intersect(o_O, d_O, t_max);
  return std::visit([&](const auto& shape) { return intersect(shape, o_O, d_O); }, e.shape);
}

RayHit SceneCaster::cast(const Eigen::Vector3d& o_C, const Eigen::Vector3d& d_C, double t_max,
                         const std::vector<Candidate>* candidates) const {
  RayHit best{t_max, RayHit::kNothing};
  auto consider = [&](int i) {
    const Entry& e = entries_[static_cast<std::size_t>(i)];
    // Bounding-sphere rejection before the exact test: behind the ray, farther than the best hit, or missed.
    const Eigen::Vector3d v = e.center_C - o_C;
    const double along = v.dot(d_C);
    const double r = e.bounding_radius;
    if (along + r < 0 || along - r > best.t) return;
    if (v.squaredNorm() - along * along > r * r) return;
    const std::optional<double> t = hit(e, o_C, d_C, best.t);
    if (t && *t <= best.t) best = RayHit{*t, e.id};
  };
  if (candidates) {
    for (const Candidate& c : *candidates) {
      if (c.min_t > best.t) break;
      consider(c.obstacle);
    }
  } else {
    for (int i = 0; i < size(); ++i) consider(i);
  }
  if (best.obstacle == RayHit::kNothing) best.t = 0;
  return best;
}

double exit_distance(const Region& bounds, const Eigen::Vector3d& o_C, const Eigen::Vector3d& d_C) {
  if (!bounds.contains(o_C)) return 0.0;
  double t = kInf;
  for (int i = 0; i < 3; ++i) {
    if (d_C[i] > kParallel) t = std::min(t, (bounds.max[i] - o_C[i]) / d_C[i]);
    if (d_C[i] < -kParallel) t = std::min(t, (bounds.min[i] - o_C[i]) / d_C[i]);
  }
  return t;
}

}  // namespace cellmap::sim
