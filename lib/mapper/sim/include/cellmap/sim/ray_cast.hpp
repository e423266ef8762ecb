// SPDX-License-Identifier: Apache-2.0
#pragma once
// Ray casting against the scene's primitives (boxes, cylinders, spheres) and the robot's collision shapes
// (primitives and triangle meshes) at its joint state.
//
// Written by hand on purpose: FCL, OctoMap and PCL cast rays against meshes or voxels, not analytically
// against a few dozen exact primitives; an analytic hit is exact (a mesh would add its own tessellation error
// to the sensor models) and a slab/quadratic test is a few lines per shape. Meshes go through a
// bounding-volume hierarchy (mesh_bvh.hpp) built once per mesh.

#include <Eigen/Geometry>

#include <memory>
#include <optional>
#include <vector>

#include "cellmap/robot/joint_state.hpp"
#include "cellmap/sim/scene.hpp"

namespace cellmap::sim {

class MeshBvh;

/// Distance t ≥ 0 along the ray o + t·d (d unit, both in the shape's frame O) to where it first enters the
/// solid; 0 when o is inside; nullopt when it misses.
[[nodiscard]] std::optional<double> intersect(const BoxShape& box, const Eigen::Vector3d& o_O,
                                              const Eigen::Vector3d& d_O);
[[nodiscard]] std::optional<double> intersect(const CylinderShape& cylinder, const Eigen::Vector3d& o_O,
                                              const Eigen::Vector3d& d_O);
[[nodiscard]] std::optional<double> intersect(const SphereShape& sphere, const Eigen::Vector3d& o_O,
                                              const Eigen::Vector3d& d_O);

/// The robot as rays see it: its collision shapes, each mesh with a bounding-volume hierarchy built once
/// (cost: O(n log n) per mesh). Immutable; a SceneCaster built with it borrows it, so it must outlive those
/// casters.
class RobotSolids final {
 public:
  explicit RobotSolids(Robot robot);
  ~RobotSolids();
  RobotSolids(RobotSolids&&) noexcept;
  RobotSolids& operator=(RobotSolids&&) noexcept;

  [[nodiscard]] const Robot& robot() const { return robot_; }

 private:
  friend class SceneCaster;
  Robot robot_;
  std::vector<std::shared_ptr<const MeshBvh>> meshes_;  // per shape; null for primitives
};

/// The first thing a ray meets.
struct RayHit final {
  static constexpr int kNothing = -1;
  static constexpr int kRobot = -2;  ///< a link of the robot or what its tool holds
  double t = 0.0;                    ///< distance along the unit direction, metres
  int obstacle = kNothing;           ///< index into the obstacles the caster was built from, or kRobot
};

/// Casts rays in the cell frame against a fixed set of obstacles and, optionally, the robot at one joint
/// state. Built once per scene state and robot state (cost: one transform per obstacle and robot shape);
/// immutable afterwards, so any number of threads may cast concurrently.
class SceneCaster final {
 public:
  explicit SceneCaster(const std::vector<Obstacle>& obstacles);
  /// The obstacles and the robot at `state`: every shape at X_CL(q) · X_LG and the payload, a box at
  /// X_CE(q) · X_EB. Hits on them report RayHit::kRobot. @throws Error as Robot::link_poses.
  SceneCaster(const std::vector<Obstacle>& obstacles, const RobotSolids& robot, const JointState& state);

  /// An obstacle a ray bundle may hit, with a lower bound on the distance to it from the bundle's apex.
  struct Candidate {
    int obstacle;
    double min_t;  ///< the obstacle's distance from the apex (no ray from the apex hits it sooner)
  };

  /// The obstacles whose bounding sphere meets the cone with apex `apex_C`, unit axis `axis_C` and half angle
  /// `half_angle` (radians, < π/2 for culling; larger keeps every obstacle), nearest first. A ray from the
  /// apex inside the cone can only hit these. Costs one distance evaluation per obstacle.
  [[nodiscard]] std::vector<Candidate> candidates(const Eigen::Vector3d& apex_C,
                                                  const Eigen::Vector3d& axis_C, double half_angle) const;

  /// The nearest hit with t ≤ t_max (t = 0 and kNothing when nothing is that near). `d_C` must be unit. With
  /// `candidates` (from candidates() for the apex o_C), only those are tested, nearest first, stopping once
  /// the next one cannot be nearer than the best hit; without, every obstacle is tested.
  [[nodiscard]] RayHit cast(const Eigen::Vector3d& o_C, const Eigen::Vector3d& d_C, double t_max,
                            const std::vector<Candidate>* candidates = nullptr) const;

  [[nodiscard]] int size() const { return static_cast<int>(entries_.size()); }

 private:
  struct Entry {
    int id;                            // obstacle index or RayHit::kRobot
    std::optional<Obstacle> obstacle;  // obstacles: for the exact distance from an apex
    Shape shape;                       // primitives
    const MeshBvh* mesh;               // meshes (owned by the RobotSolids), else null
    Eigen::Matrix3d R_OC;              // rotates cell-frame vectors into the shape frame
    Eigen::Vector3d p_CO;              // shape frame origin in the cell
    Eigen::Vector3d center_C;          // centre of the bounding sphere
    double bounding_radius;
  };
  void add_obstacles(const std::vector<Obstacle>& obstacles);
  void add_robot_shape(const LinkGeometry& geometry, const MeshBvh* mesh, const Eigen::Isometry3d& X_CG);
  [[nodiscard]] std::optional<double> hit(const Entry& entry, const Eigen::Vector3d& o_C,
                                          const Eigen::Vector3d& d_C, double t_max) const;

  std::vector<Entry> entries_;
};

/// Distance along the ray o + t·d (d unit) at which it leaves the bounds; 0 if o is outside.
[[nodiscard]] double exit_distance(const Region& bounds, const Eigen::Vector3d& o_C,
                                   const Eigen::Vector3d& d_C);

}  // namespace cellmap::sim
