#include "cellmap/robot/robot.hpp"

#include <cmath>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

bool all_finite(const Eigen::Isometry3d& X) {
  return X.matrix().allFinite();
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

Robot Robot::serial(const std::string& root_link, const std::vector<ChainJoint>& joints,
                    const Eigen::Isometry3d& X_C_root) {
  if (!all_finite(X_C_root)) throw Error("robot base pose must be finite");
  Robot robot;
  robot.X_C_root_ = X_C_root;
  robot.add_step({root_link, Eigen::Isometry3d::Identity(), JointType::kFixed, Eigen::Vector3d::UnitZ(), -1},
                 "", {});
  for (const ChainJoint& joint : joints) {
    Step step{joint.link, joint.origin, joint.type, joint.axis, -1};
    if (step.type != JointType::kFixed) {
      if (!(step.axis.norm() > 0)) throw Error("joint '" + joint.joint + "' has a zero axis");
      step.axis.normalize();
    }
    robot.add_step(step, joint.joint, joint.limits);
  }
  robot.validate();
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
