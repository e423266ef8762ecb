// SPDX-License-Identifier: Apache-2.0
#include "cellmap/urdf/urdf_model.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <filesystem>
#include <map>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/urdf/mesh_file.hpp"

namespace cellmap {
namespace {

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  double w = 1, x = 0, y = 0, z = 0;
  pose.rotation.getQuaternion(x, y, z, w);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  X.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return X;
}

// The joint above `link` as a chain joint (type, limits, axis). Throws without the source prefix.
Robot::ChainJoint chain_joint(const urdf::Link& link) {
  const urdf::Joint& joint = *link.parent_joint;
  Robot::ChainJoint out;
  out.joint = joint.name;
  out.link = link.name;
  out.origin = to_isometry(joint.parent_to_joint_origin_transform);
  out.axis = Eigen::Vector3d(joint.axis.x, joint.axis.y, joint.axis.z);
  switch (joint.type) {
    case urdf::Joint::FIXED:
      out.type = Robot::JointType::kFixed;
      break;
    case urdf::Joint::PRISMATIC:
    case urdf::Joint::REVOLUTE:
      out.type =
          joint.type == urdf::Joint::PRISMATIC ? Robot::JointType::kPrismatic : Robot::JointType::kRevolute;
      if (!joint.limits) throw Error("joint '" + joint.name + "' has no <limit>");
      out.limits = {joint.limits->lower, joint.limits->upper};
      break;
    case urdf::Joint::CONTINUOUS:
      out.type = Robot::JointType::kRevolute;
      out.limits = {-M_PI, M_PI};
      break;
    default:
      throw Error("joint '" + joint.name + "' has an unsupported type (floating or planar)");
  }
  return out;
}

// Meshes read so far, by file and scale: links sharing a file share the mesh.
class MeshCache {
 public:
  std::shared_ptr<const TriangleMesh> get(const std::filesystem::path& file, const Eigen::Vector3d& scale) {
    const std::string key = file.string() + "|" + std::to_string(scale.x()) + "," +
                            std::to_string(scale.y()) + "," + std::to_string(scale.z());
    auto& mesh = meshes_[key];
    if (!mesh) mesh = std::make_shared<const TriangleMesh>(load_mesh(file, scale));
    return mesh;
  }

 private:
  std::map<std::string, std::shared_ptr<const TriangleMesh>> meshes_;
};

LinkGeometry link_geometry(const urdf::Geometry& geometry, const std::string& base_dir,
                           const std::vector<std::string>& package_paths, MeshCache& meshes) {
  switch (geometry.type) {
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(geometry);
      return BoxShape{0.5 * Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z)};
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
      return CylinderShape{cylinder.radius, 0.5 * cylinder.length};
    }
    case urdf::Geometry::SPHERE:
      return SphereShape{static_cast<const urdf::Sphere&>(geometry).radius};
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(geometry);
      const Eigen::Vector3d scale(mesh.scale.x, mesh.scale.y, mesh.scale.z);
      return MeshShape{meshes.get(resolve_mesh_uri(mesh.filename, base_dir, package_paths), scale)};
    }
  }
  throw Error("unknown geometry type");
}

}  // namespace

UrdfModel::UrdfModel(std::shared_ptr<const urdf::ModelInterface> model, std::string source,
                     std::string base_dir)
    : model_(std::move(model)), source_(std::move(source)), base_dir_(std::move(base_dir)) {}

UrdfModel UrdfModel::parse(const std::string& xml, const std::string& source, const std::string& base_dir) {
  // urdfdom reports parse problems through console_bridge on stderr; the library reports through Error only.
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
  if (!model) throw Error(source + ": not a valid URDF robot description");
  return UrdfModel(std::move(model), source, base_dir);
}

UrdfModel UrdfModel::load(const std::string& path) {
  const std::string folder = std::filesystem::path(path).parent_path().string();
  return parse(read_file(path), path, folder.empty() ? "." : folder);
}

Robot UrdfModel::chain(const std::string& tool_link, const Eigen::Isometry3d& X_C_root) const {
  urdf::LinkConstSharedPtr link = model_->getLink(tool_link);
  if (!link) throw Error(source_ + ": tool link '" + tool_link + "' is not in the URDF");
  try {
    // Walk from the tool up to the root, then list the joints root first. urdfdom accepts joints that close a
    // loop away from the root, so a walk longer than the model has links is a loop.
    std::vector<Robot::ChainJoint> joints;
    for (; link->getParent(); link = link->getParent()) {
      if (joints.size() == model_->links_.size())
        throw Error("the links from '" + tool_link + "' up to the root form a loop");
      joints.push_back(chain_joint(*link));
    }
    return Robot::serial(link->name, {joints.rbegin(), joints.rend()}, X_C_root);
  } catch (const Error& e) {
    throw Error(source_ + ": " + e.what());
  }
}

std::vector<LinkShape> UrdfModel::link_shapes(const Robot& robot,
                                              const std::vector<std::string>& package_paths) const {
  std::vector<LinkShape> shapes;
  MeshCache meshes;
  for (const std::string& name : robot.link_names()) {
    const urdf::LinkConstSharedPtr link = model_->getLink(name);
    if (!link) continue;  // a link the robot's chain names but this URDF does not: no geometry
    for (std::size_t i = 0; i < link->collision_array.size(); ++i) {
      const urdf::CollisionSharedPtr& collision = link->collision_array[i];
      if (!collision || !collision->geometry) continue;
      const std::string what = source_ + ": link '" + name + "' collision " + std::to_string(i);
      try {
        LinkShape shape{name, to_isometry(collision->origin),
                        link_geometry(*collision->geometry, base_dir_, package_paths, meshes)};
        validate_shape(shape, what);
        shapes.push_back(std::move(shape));
      } catch (const Error& e) {
        const std::string reason = e.what();
        throw Error(reason.rfind(what, 0) == 0 ? reason : what + ": " + reason);
      }
    }
  }
  return shapes;
}

Robot UrdfModel::robot(const std::string& tool_link, const Eigen::Isometry3d& X_C_root,
                       const std::vector<std::string>& package_paths) const {
  const Robot chained = chain(tool_link, X_C_root);
  return chained.with_shapes(link_shapes(chained, package_paths));
}

}  // namespace cellmap
