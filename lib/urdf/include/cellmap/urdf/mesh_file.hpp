// SPDX-License-Identifier: Apache-2.0
#pragma once
// Triangle meshes read from files (STL, COLLADA .dae, OBJ, and what else assimp reads) and the mesh URIs of
// robot descriptions resolved to files. The one place cellmap links assimp.

#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <vector>

#include "cellmap/robot/geometry.hpp"

namespace cellmap {

/// The triangles of every mesh in the file, merged into one mesh in the file's frame (each node's transform
/// applied; COLLADA's unit applied, its up axis not, as URDF expects), every vertex multiplied componentwise
/// by `scale`. Corners at the same position are one vertex; points and lines are dropped.
/// @throws Error "<path>: <reason>" if the file cannot be read or parsed, or holds no triangle.
[[nodiscard]] TriangleMesh load_mesh(const std::filesystem::path& path,
                                     const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

/// The file a URDF mesh URI names:
/// - `package://NAME/REST`: REST under the package folder NAME, looked for first in each of `package_paths`
///   (the folder itself if its name is NAME, else a folder NAME inside it), then among `base_dir` and its
///   ancestors (the URDF usually lives inside its package, e.g. NAME/urdf/robot.urdf);
/// - `file:///abs/path`: that path;
/// - anything else: a path, relative ones resolved against `base_dir` (the URDF file's folder).
/// @throws Error naming the URI if the file does not exist.
[[nodiscard]] std::filesystem::path resolve_mesh_uri(const std::string& uri,
                                                     const std::filesystem::path& base_dir,
                                                     const std::vector<std::string>& package_paths = {});

}  // namespace cellmap
