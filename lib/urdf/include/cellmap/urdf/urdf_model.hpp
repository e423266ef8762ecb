#pragma once
// Reading a robot from URDF (urdfdom): its serial chain for forward kinematics and the box collision geometry
// of its links. The one place cellmap parses URDF; a planner that builds its Robot otherwise never links
// urdfdom.

#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <vector>

#include "cellmap/robot/robot.hpp"

namespace urdf {
class ModelInterface;
}

namespace cellmap {

/// A URDF robot description, parsed once. Immutable; safe to share between threads.
class UrdfModel final {
 public:
  /// Parses URDF XML text; `source` names it in every error message.
  /// @throws Error "<source>: not a valid URDF robot description" if it does not parse.
  [[nodiscard]] static UrdfModel parse(const std::string& xml, const std::string& source = "urdf");
  /// Reads and parses a URDF file (errors name the path). @throws Error if it cannot be read or parsed.
  [[nodiscard]] static UrdfModel load(const std::string& path);

  /// The chain from the URDF's root link to `tool_link`, with the root placed at X_C_root. Fixed joints stay
  /// links of the chain; revolute, continuous (limits ±π) and prismatic joints become moving joints.
  /// @throws Error naming the source and the reason if `tool_link` is missing, a joint type is not supported
  /// (floating, planar), a moving joint has no <limit> or a zero axis, or X_C_root is not finite.
  [[nodiscard]] Robot chain(const std::string& tool_link,
                            const Eigen::Isometry3d& X_C_root = Eigen::Isometry3d::Identity()) const;

  /// The box collision geometry of `robot`'s links: every <collision> of a link in robot.link_names() becomes
  /// a LinkBox (X_LB = the collision origin, half extents = size / 2); links outside the chain are ignored.
  /// @throws Error naming the source, link and collision if a chain link has non-box collision geometry (a
  /// skipped shape would silently hide an obstacle).
  [[nodiscard]] std::vector<LinkBox> link_boxes(const Robot& robot) const;

  [[nodiscard]] const std::string& source() const { return source_; }

 private:
  UrdfModel(std::shared_ptr<const urdf::ModelInterface> model, std::string source);

  std::shared_ptr<const urdf::ModelInterface> model_;
  std::string source_;
};

}  // namespace cellmap
