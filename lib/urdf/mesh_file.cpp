// SPDX-License-Identifier: Apache-2.0
#include "cellmap/urdf/mesh_file.hpp"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <array>
#include <map>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;

// Builds one mesh with every position stored once. assimp's own joining keeps a corner once per face normal
// (STL files store one normal per face), so corners are joined here by position alone.
class MeshBuilder {
 public:
  explicit MeshBuilder(const Eigen::Vector3d& scale) : scale_(scale) {}

  // Appends the triangles of `node`'s meshes and its children's, placed by the accumulated node transform.
  void append(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent) {
    const aiMatrix4x4 transform = parent * node.mTransformation;
    for (unsigned m = 0; m < node.mNumMeshes; ++m) {
      const aiMesh& mesh = *scene.mMeshes[node.mMeshes[m]];
      for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
        const aiFace& face = mesh.mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines have no surface
        Eigen::Vector3i triangle;
        for (int corner = 0; corner < 3; ++corner) {
          triangle[corner] = vertex(transform * mesh.mVertices[face.mIndices[corner]]);
        }
        mesh_.triangles.push_back(triangle);
      }
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) append(scene, *node.mChildren[c], transform);
  }

  TriangleMesh take() { return std::move(mesh_); }

 private:
  int vertex(const aiVector3D& p) {
    const std::array<double, 3> key{scale_.x() * p.x, scale_.y() * p.y, scale_.z() * p.z};
    const auto [it, added] = index_.emplace(key, static_cast<int>(mesh_.vertices.size()));
    if (added) mesh_.vertices.emplace_back(key[0], key[1], key[2]);
    return it->second;
  }

  Eigen::Vector3d scale_;
  std::map<std::array<double, 3>, int> index_;
  TriangleMesh mesh_;
};

// `package://NAME/REST` → the package folder NAME, or an empty path.
fs::path find_package(const std::string& name, const fs::path& base_dir,
                      const std::vector<std::string>& package_paths) {
  for (const std::string& entry : package_paths) {
    const fs::path path(entry);
    if (path.filename() == name && fs::is_directory(path)) return path;
    if (fs::is_directory(path / name)) return path / name;
  }
  for (fs::path dir = fs::absolute(base_dir); !dir.empty(); dir = dir.parent_path()) {
    if (dir.filename() == name) return dir;
    if (dir == dir.parent_path()) break;
  }
  return {};
}

}  // namespace

TriangleMesh load_mesh(const fs::path& path, const Eigen::Vector3d& scale) {
  Assimp::Importer importer;
  // URDF meshes are in the link frame as written: keep COLLADA's z-up data as it is.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const aiScene* scene = importer.ReadFile(path.string(), aiProcess_Triangulate);
  if (!scene || !scene->mRootNode) {
    throw Error(path.string() + ": cannot read mesh: " + importer.GetErrorString());
  }
  MeshBuilder builder(scale);
  builder.append(*scene, *scene->mRootNode, aiMatrix4x4());
  TriangleMesh mesh = builder.take();
  if (mesh.triangles.empty()) throw Error(path.string() + ": mesh file holds no triangle");
  mesh.validate(path.string());
  return mesh;
}

fs::path resolve_mesh_uri(const std::string& uri, const fs::path& base_dir,
                          const std::vector<std::string>& package_paths) {
  const std::string package_scheme = "package://", file_scheme = "file://";
  fs::path path;
  if (uri.rfind(package_scheme, 0) == 0) {
    const std::string rest = uri.substr(package_scheme.size());
    const std::size_t slash = rest.find('/');
    const std::string name = rest.substr(0, slash);
    const fs::path package = find_package(name, base_dir, package_paths);
    if (package.empty()) {
      throw Error("mesh '" + uri + "': package '" + name +
                  "' not found (give its folder or its parent as a package path)");
    }
    path = slash == std::string::npos ? package : package / rest.substr(slash + 1);
  } else if (uri.rfind(file_scheme, 0) == 0) {
    path = uri.substr(file_scheme.size());
  } else {
    path = fs::path(uri).is_relative() ? base_dir / uri : fs::path(uri);
  }
  if (!fs::is_regular_file(path)) throw Error("mesh '" + uri + "': no file " + path.string());
  return path;
}

}  // namespace cellmap
