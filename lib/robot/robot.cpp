#include "cellmap/robot/robot.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <cmath>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

bool all_finite(const Eigen::Isometry3d& X) {
  return X.matrix().allFinite();
}

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  double w = 1, x = 0, y = 0, z = 0;
  pose.rotation.getQuaternion(x, y, z, w);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  X.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return X;
}

}  // namespace

Robot Robot::gantry(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                    const Eigen::Isometry3d& X_CE_zero) {
  if (!lower.allFinite() || !upper.allFinite() || !all_finite(X_CE_zero)) {
    throw Error("gantry: axis ranges and tool pose must be finite");
  }
  Robot robot;
  robot.add_step({"base", Eigen::Isometry3d::Identity(), JointType::kFixed, Eigen::Vector3d::UnitZ(), -1}, "",
                 {});
  const char* links[] = {"bridge", "carriage", "ram"};
  const char* joints[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    robot.add_step(
        {links[axis], Eigen::Isometry3d::Identity(), JointType::kPrismatic, Eigen::Vector3d::Unit(axis), -1},
        joints[axis], {lower[axis], upper[axis]});
  }
  // The tool pose at q = 0 is carried by the ram's frame: X_CE(q) = Translation(q) * X_CE_zero.
  robot.steps_[1].origin = X_CE_zero;
  robot.steps_[1].axis = X_CE_zero.linear().transpose() * Eigen::Vector3d::UnitX();
  robot.steps_[2].axis = X_CE_zero.linear().transpose() * Eigen::Vector3d::UnitY();
  robot.steps_[3].axis = X_CE_zero.linear().transpose() * Eigen::Vector3d::UnitZ();
  robot.validate();
  return robot;
}

Robot Robot::from_urdf_file(const std::string& path, const std::string& tool_link,
                            const Eigen::Isometry3d& X_C_root) {
  return from_urdf_string(read_file(path), tool_link, X_C_root, path);
}

Robot Robot::from_urdf_string(const std::string& xml, const std::string& tool_link,
                              const Eigen::Isometry3d& X_C_root, const std::string& source) {
  // urdfdom reports parse problems through console_bridge on stderr; the library reports through Error only.
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
  if (!model) throw Error(source + ": not a valid URDF robot description");
  if (!all_finite(X_C_root)) throw Error(source + ": robot base pose must be finite");
  urdf::LinkConstSharedPtr link = model->getLink(tool_link);
  if (!link) throw Error(source + ": tool link '" + tool_link + "' is not in the URDF");

  // Walk from the tool up to the root, then build the chain root first.
  std::vector<urdf::LinkConstSharedPtr> chain;
  for (; link; link = link->getParent()) chain.push_back(link);

  Robot robot;
  robot.X_C_root_ = X_C_root;
  robot.add_step(
      {chain.back()->name, Eigen::Isometry3d::Identity(), JointType::kFixed, Eigen::Vector3d::UnitZ(), -1},
      "", {});
  for (auto it = chain.rbegin() + 1; it != chain.rend(); ++it) {
    const urdf::JointConstSharedPtr joint = (*it)->parent_joint;
    Step step;
    step.link = (*it)->name;
    step.origin = to_isometry(joint->parent_to_joint_origin_transform);
    step.axis = Eigen::Vector3d(joint->axis.x, joint->axis.y, joint->axis.z);
    JointLimits limits;
    switch (joint->type) {
      case urdf::Joint::FIXED:
        step.type = JointType::kFixed;
        break;
      case urdf::Joint::PRISMATIC:
      case urdf::Joint::REVOLUTE:
        step.type = joint->type == urdf::Joint::PRISMATIC ? JointType::kPrismatic : JointType::kRevolute;
        if (!joint->limits) throw Error(source + ": joint '" + joint->name + "' has no <limit>");
        limits = {joint->limits->lower, joint->limits->upper};
        break;
      case urdf::Joint::CONTINUOUS:
        step.type = JointType::kRevolute;
        limits = {-M_PI, M_PI};
        break;
      default:
        throw Error(source + ": joint '" + joint->name + "' has an unsupported type (floating or planar)");
    }
    if (step.type != JointType::kFixed) {
      if (!(step.axis.norm() > 0)) throw Error(source + ": joint '" + joint->name + "' has a zero axis");
      step.axis.normalize();
    }
    robot.add_step(step, joint->name, limits);
  }
  try {
    robot.validate();
  } catch (const Error& e) {
    throw Error(source + ": " + e.what());
  }
  return robot;
}

void Robot::add_step(Step step, const std::string& joint_name, const JointLimits& limits) {
  if (step.type != JointType::kFixed) {
    step.joint_index = static_cast<int>(joint_names_.size());
    joint_names_.push_back(joint_name);
    limits_.push_back(limits);
  }
  link_names_.push_back(step.link);
  steps_.push_back(std::move(step));
}

void Robot::validate() const {
  for (std::size_t i = 0; i < limits_.size(); ++i) {
    const JointLimits& l = limits_[i];
    if (!std::isfinite(l.lower) || !std::isfinite(l.upper) || l.lower > l.upper) {
      throw Error("joint '" + joint_names_[i] + "': limits must be finite with lower <= upper");
    }
  }
  for (const Step& step : steps_) {
    if (!all_finite(step.origin) || !step.axis.allFinite()) {
      throw Error("link '" + step.link + "': pose must be finite");
    }
  }
}

bool Robot::within_limits(const Eigen::VectorXd& q) const {
  if (q.size() != dof() || !q.allFinite()) return false;
  for (int i = 0; i < dof(); ++i) {
    if (q[i] < limits_[i].lower || q[i] > limits_[i].upper) return false;
  }
  return true;
}

std::vector<Eigen::Isometry3d> Robot::link_poses(const Eigen::VectorXd& q) const {
  if (q.size() != dof()) {
    throw Error("robot: joint vector has " + std::to_string(q.size()) + " entries, the robot has " +
                std::to_string(dof()) + " joints");
  }
  if (!q.allFinite()) throw Error("robot: joint vector has a non-finite entry");
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(steps_.size());
  Eigen::Isometry3d X_CL = X_C_root_;
  for (const Step& step : steps_) {
    X_CL = X_CL * step.origin;
    if (step.type == JointType::kPrismatic) {
      X_CL.translate(q[step.joint_index] * step.axis);
    } else if (step.type == JointType::kRevolute) {
      X_CL.rotate(Eigen::AngleAxisd(q[step.joint_index], step.axis));
    }
    poses.push_back(X_CL);
  }
  return poses;
}

Eigen::Isometry3d Robot::tool_pose(const Eigen::VectorXd& q) const {
  return link_poses(q).back();
}

}  // namespace cellmap
