// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading a robot from URDF (urdfdom): its serial chain for forward kinematics and the collision geometry of
// its links (boxes, cylinders, spheres, meshes read with assimp: mesh_file.hpp). The one place cellmap parses
// URDF; a planner that builds its Robot otherwise links neither urdfdom nor assimp.

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
  /// Parses URDF XML text; `source` names it in every error message, `base_dir` resolves its mesh URIs
  /// (resolve_mesh_uri). @throws Error "<source>: not a valid URDF robot description" if it does not parse.
  [[nodiscard]] static UrdfModel parse(const std::string& xml, const std::string& source = "urdf",
                                       const std::string& base_dir = ".");
  /// Reads and parses a URDF file (errors name the path; mesh URIs resolve against its folder).
  /// @throws Error if it cannot be read or parsed.
  [[nodiscard]] static UrdfModel load(const std::string& path);

  /// The chain from the URDF's root link to `tool_link`, with the root placed at X_C_root. Fixed joints stay
  /// links of the chain; revolute, continuous (limits ±π) and prismatic joints become moving joints.
  /// @throws Error naming the source and the reason if `tool_link` is missing, a joint type is not supported
  /// (floating, planar), a moving joint has no <limit> or a zero axis, or X_C_root is not finite.
  [[nodiscard]] Robot chain(const std::string& tool_link,
                            const Eigen::Isometry3d& X_C_root = Eigen::Isometry3d::Identity()) const;

  /// The collision geometry of `robot`'s links: every <collision> of a link in robot.link_names() becomes a
  /// LinkShape (X_LG = the collision origin; box size / 2, cylinder radius and length / 2 about its z,
  /// sphere, mesh loaded with its scale, each file once); links outside the chain are ignored.
  /// `package_paths` help find `package://` meshes (resolve_mesh_uri).
  /// @throws Error naming the source, link and collision if a mesh cannot be found or read or a size is not
  /// positive (a skipped shape would silently hide an obstacle).
  [[nodiscard]] std::vector<LinkShape> link_shapes(const Robot& robot,
                                                   const std::vector<std::string>& package_paths = {}) const;

  /// chain(tool_link, X_C_root) with link_shapes() as its collision geometry. @throws Error as both.
  [[nodiscard]] Robot robot(const std::string& tool_link,
                            const Eigen::Isometry3d& X_C_root = Eigen::Isometry3d::Identity(),
                            const std::vector<std::string>& package_paths = {}) const;

  [[nodiscard]] const std::string& source() const { return source_; }

 private:
  UrdfModel(std::shared_ptr<const urdf::ModelInterface> model, std::string source, std::string base_dir);

  std::shared_ptr<const urdf::ModelInterface> model_;
  std::string source_;
  std::string base_dir_;
};

}  // namespace cellmap
