// SPDX-License-Identifier: Apache-2.0
#pragma once
// The robot model: kinematics (joint vector q → pose of every link and of the tool in the cell frame) and the
// collision geometry fixed to its links (boxes, cylinders, spheres, triangle meshes). One model serves the
// planner's robot boxes, the simulator and the self filter. Reading a URDF and its meshes is a separate stage
// (cellmap/urdf/urdf_model.hpp), so this one needs Eigen only.

#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "cellmap/robot/geometry.hpp"

namespace cellmap {

/// Range of one joint: metres for prismatic joints, radians for revolute ones.
struct JointLimits final {
  double lower = 0.0;
  double upper = 0.0;
};

/// The built-in gantry's moving parts as boxes, each given by its centre and half extents in the cell frame
/// at q = 0 (axis-aligned there; metres, half extents > 0).
struct GantryParts final {
  struct Part {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Vector3d half_extents = Eigen::Vector3d::Ones();
  };
  Part bridge;    ///< moves with x
  Part carriage;  ///< moves with x and y
  Part ram;       ///< moves with x, y and z: the column that carries the tool

  /// Parts that fit a gantry with these axis ranges and tool pose at q = 0 (p0 = its position): a 0.15 m
  /// square ram from the flange up to the carriage's top even at the lowest z, a 0.4 × 0.4 × 0.3 m carriage
  /// 0.1 m above the flange's highest position, and a 0.3 × 0.3 m bridge beam on the carriage spanning the
  /// y travel and 0.3 m beyond it on each side.
  [[nodiscard]] static GantryParts fitting(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                                           const Eigen::Isometry3d& X_CE_zero);
};

/// A serial kinematic chain placed in the cell frame C with collision shapes on its links: a linear/gantry
/// robot (built in) or a serial arm (e.g. read from URDF by UrdfModel). Links are listed base first, tool
/// last; each moving joint drives the link after it. Immutable after construction (shapes share their
/// meshes), so it can be shared between threads. An object that exists is valid.
class Robot final {
 public:
  enum class JointType { kFixed, kPrismatic, kRevolute };

  /// One joint of a serial chain with the link it carries (a URDF joint and its child link).
  struct ChainJoint {
    std::string joint;                                         ///< moving joints name the entries of q
    std::string link;                                          ///< the child link
    Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  ///< joint frame in the parent link frame
    JointType type = JointType::kFixed;
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< in the joint frame, any length > 0 (moving joints)
    JointLimits limits;                               ///< moving joints
  };

  /// A gantry with three prismatic axes along the cell's x, y and z: the bridge (x), the carriage (y) and the
  /// ram (z). q = (x, y, z) in metres; the tool pose is X_CE(q) = Translation(q) * X_CE_zero, so `X_CE_zero`
  /// is the tool pose at q = 0 (its rotation fixes how the tool, and a sensor on it, looks down).
  /// Links: "base" (the cell frame), "bridge", "carriage", "ram"; each moving link's frame is the tool frame
  /// moved by the axes up to it (bridge: x only, carriage: x and y), and the tool frame is the ram's.
  /// @throws Error if a lower limit exceeds its upper limit or a value is not finite.
  [[nodiscard]] static Robot gantry(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                                    const Eigen::Isometry3d& X_CE_zero = Eigen::Isometry3d::Identity());
  /// As above, with `parts` as the collision shapes of the bridge, carriage and ram links.
  /// @throws Error as above, or naming the part if a size is not positive.
  [[nodiscard]] static Robot gantry(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                                    const Eigen::Isometry3d& X_CE_zero, const GantryParts& parts);

  /// The chain `root_link` → joints[0].link → ... → joints.back().link (the tool), with the root link placed
  /// at X_C_root. Fixed joints stay in the chain (their links get poses, no entry of q).
  /// @throws Error naming the joint or link if a moving joint's axis is zero, its limits are not finite with
  /// lower <= upper, or a pose is not finite.
  [[nodiscard]] static Robot serial(const std::string& root_link, const std::vector<ChainJoint>& joints,
                                    const Eigen::Isometry3d& X_C_root = Eigen::Isometry3d::Identity());

  /// Number of moving joints (the size of q).
  [[nodiscard]] int dof() const { return static_cast<int>(joint_names_.size()); }
  [[nodiscard]] const std::vector<std::string>& joint_names() const { return joint_names_; }
  [[nodiscard]] const std::vector<JointLimits>& limits() const { return limits_; }
  /// Names of the links along the chain, base first, tool link last.
  [[nodiscard]] const std::vector<std::string>& link_names() const { return link_names_; }

  /// True if q has dof() finite entries, each within its limits (inclusive).
  [[nodiscard]] bool within_limits(const Eigen::VectorXd& q) const;

  /// X_CL for every link, in link_names() order. Costs one transform product per joint.
  /// @throws Error if q has the wrong size or a non-finite entry (limits are not enforced here).
  [[nodiscard]] std::vector<Eigen::Isometry3d> link_poses(const Eigen::VectorXd& q) const;
  /// X_CE: the pose of the tool (last) link. @throws Error as link_poses.
  [[nodiscard]] Eigen::Isometry3d tool_pose(const Eigen::VectorXd& q) const;

  /// This robot with `shapes` as its collision geometry (replacing any it had).
  /// @throws Error naming the shape index and link if the link is not one of link_names() or the shape is
  /// invalid (validate_shape).
  [[nodiscard]] Robot with_shapes(std::vector<LinkShape> shapes) const;
  /// The collision shapes, each on a link of the chain; empty for a kinematics-only robot.
  [[nodiscard]] const std::vector<LinkShape>& shapes() const { return shapes_; }
  /// Index into link_names() of every shape's link, in shapes() order.
  [[nodiscard]] const std::vector<int>& shape_links() const { return shape_links_; }
  /// X_CG of every shape at q (X_CL(q) · X_LG), in shapes() order. @throws Error as link_poses.
  [[nodiscard]] std::vector<Eigen::Isometry3d> shape_poses(const Eigen::VectorXd& q) const;
  /// The tight box of every shape on its link (bounding_box), in shapes() order: the boxes a planner's
  /// RobotBoxes checks.
  [[nodiscard]] std::vector<LinkBox> shape_boxes() const;
  /// Triangles of all mesh shapes.
  [[nodiscard]] std::size_t triangle_count() const;

  /// One step of the chain: link i is placed at X_parent_link(i) = origin * motion(q_i) (motion is identity
  /// for fixed steps). Public so that tests and tools can inspect the chain.
  struct Step {
    std::string link;
    Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  ///< joint frame in the parent link frame
    JointType type = JointType::kFixed;
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< unit, in the joint frame
    int joint_index = -1;                             ///< index into q, -1 for fixed steps
  };
  [[nodiscard]] const std::vector<Step>& steps() const { return steps_; }

 private:
  Robot() = default;
  void add_step(Step step, const std::string& joint_name, const JointLimits& limits);
  void validate() const;

  Eigen::Isometry3d X_C_root_ = Eigen::Isometry3d::Identity();
  std::vector<Step> steps_;  // steps_[0] is the root link (fixed, origin identity)
  std::vector<std::string> joint_names_;
  std::vector<JointLimits> limits_;
  std::vector<std::string> link_names_;
  std::vector<LinkShape> shapes_;
  std::vector<int> shape_links_;
};

}  // namespace cellmap
