#pragma once
// Analytic ray casting against the scene's primitives (boxes, cylinders, spheres).
//
// Written by hand on purpose: FCL, OctoMap and PCL cast rays against meshes or voxels, not analytically
// against a few dozen exact primitives; an analytic hit is exact (a mesh would add its own tessellation error
// to the sensor models) and a slab/quadratic test is a few lines per shape.

#include <Eigen/Geometry>

#include <optional>
#include <vector>

#include "cellmap/sim/scene.hpp"

namespace cellmap::sim {

/// Distance t ≥ 0 along the ray o + t·d (d unit, both in the shape's frame O) to where it first enters the
/// solid; 0 when o is inside; nullopt when it misses.
[[nodiscard]] std::optional<double> intersect(const BoxShape& box, const Eigen::Vector3d& o_O,
                                              const Eigen::Vector3d& d_O);
[[nodiscard]] std::optional<double> intersect(const CylinderShape& cylinder, const Eigen::Vector3d& o_O,
                                              const Eigen::Vector3d& d_O);
[[nodiscard]] std::optional<double> intersect(const SphereShape& sphere, const Eigen::Vector3d& o_O,
                                              const Eigen::Vector3d& d_O);

/// The first obstacle a ray meets.
struct RayHit final {
  double t = 0.0;     ///< distance along the unit direction, metres
  int obstacle = -1;  ///< index into the obstacles the caster was built from; -1 when nothing was hit
};

/// Casts rays in the cell frame against a fixed set of obstacles. Built once per scene state (cost: one
/// transform per obstacle); immutable afterwards, so any number of threads may cast concurrently.
class SceneCaster final {
 public:
  explicit SceneCaster(const std::vector<Obstacle>& obstacles);

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

  /// The nearest hit with t ≤ t_max. `d_C` must be unit. With `candidates` (from candidates() for the apex
  /// o_C), only those are tested, nearest first, stopping once the next one cannot be nearer than the best
  /// hit; without, every obstacle is tested.
  [[nodiscard]] RayHit cast(const Eigen::Vector3d& o_C, const Eigen::Vector3d& d_C, double t_max,
                            const std::vector<Candidate>* candidates = nullptr) const;

  [[nodiscard]] int size() const { return static_cast<int>(entries_.size()); }

 private:
  struct Entry {
    Obstacle obstacle;
    Shape shape;
    Eigen::Matrix3d R_OC;  // rotates cell-frame vectors into the obstacle frame
    Eigen::Vector3d p_CO;  // obstacle frame origin in the cell
    double bounding_radius;
  };
  [[nodiscard]] std::optional<double> hit(const Entry& entry, const Eigen::Vector3d& o_C,
                                          const Eigen::Vector3d& d_C) const;

  std::vector<Entry> entries_;
};

/// Distance along the ray o + t·d (d unit) at which it leaves the bounds; 0 if o is outside.
[[nodiscard]] double exit_distance(const Region& bounds, const Eigen::Vector3d& o_C,
                                   const Eigen::Vector3d& d_C);

}  // namespace cellmap::sim
