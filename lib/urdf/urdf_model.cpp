#include "cellmap/urdf/urdf_model.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <cmath>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"

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

}  // namespace

UrdfModel::UrdfModel(std::shared_ptr<const urdf::ModelInterface> model, std::string source)
    : model_(std::move(model)), source_(std::move(source)) {}

UrdfModel UrdfModel::parse(const std::string& xml, const std::string& source) {
  // urdfdom reports parse problems through console_bridge on stderr; the library reports through Error only.
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
  if (!model) throw Error(source + ": not a valid URDF robot description");
  return UrdfModel(std::move(model), source);
}

UrdfModel UrdfModel::load(const std::string& path) {
  return parse(read_file(path), path);
}

Robot UrdfModel::chain(const std::string& tool_link, const Eigen::Isometry3d& X_C_root) const {
  urdf::LinkConstSharedPtr link = model_->getLink(tool_link);
  if (!link) throw Error(source_ + ": tool link '" + tool_link + "' is not in the URDF");
  try {
    // Walk from the tool up to the root, then list the joints root first.
    std::vector<Robot::ChainJoint> joints;
    for (; link->getParent(); link = link->getParent()) joints.push_back(chain_joint(*link));
    return Robot::serial(link->name, {joints.rbegin(), joints.rend()}, X_C_root);
  } catch (const Error& e) {
    throw Error(source_ + ": " + e.what());
  }
}

std::vector<LinkBox> UrdfModel::link_boxes(const Robot& robot) const {
  std::vector<LinkBox> boxes;
  for (const std::string& name : robot.link_names()) {
    const urdf::LinkConstSharedPtr link = model_->getLink(name);
    if (!link) continue;  // a link the robot's chain names but this URDF does not: no geometry
    for (std::size_t i = 0; i < link->collision_array.size(); ++i) {
      const urdf::CollisionSharedPtr& collision = link->collision_array[i];
      if (!collision || !collision->geometry) continue;
      if (collision->geometry->type != urdf::Geometry::BOX) {
        throw Error(source_ + ": link '" + name + "' collision " + std::to_string(i) +
                    ": only box geometry is supported");
      }
      const auto& box = static_cast<const urdf::Box&>(*collision->geometry);
      boxes.push_back(
          {name, to_isometry(collision->origin), 0.5 * Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z)});
    }
  }
  return boxes;
}

}  // namespace cellmap
