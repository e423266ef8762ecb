// SPDX-License-Identifier: Apache-2.0
#include "cellmap/robot/robot.hpp"

#include <algorithm>
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

GantryParts GantryParts::fitting(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                                 const Eigen::Isometry3d& X_CE_zero) {
  const Eigen::Vector3d p0 = X_CE_zero.translation();
  GantryParts parts;
  const double carriage_bottom = p0.z() + upper.z() + 0.1;
  parts.carriage = {{p0.x(), p0.y(), carriage_bottom + 0.15}, {0.2, 0.2, 0.15}};
  const double carriage_top = carriage_bottom + 0.3;
  // The ram's top at q_z = lower.z still reaches the carriage's top.
  const double ram_top = carriage_top - std::min(lower.z(), 0.0);
  parts.ram = {{p0.x(), p0.y(), 0.5 * (p0.z() + ram_top)}, {0.075, 0.075, 0.5 * (ram_top - p0.z())}};
  const double y_min = p0.y() + lower.y() - 0.3, y_max = p0.y() + upper.y() + 0.3;
  parts.bridge = {{p0.x(), 0.5 * (y_min + y_max), carriage_top + 0.15}, {0.15, 0.5 * (y_max - y_min), 0.15}};
  return parts;
}

Robot Robot::gantry(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                    const Eigen::Isometry3d& X_CE_zero, const GantryParts& parts) {
  const Robot robot = gantry(lower, upper, X_CE_zero);
  // Parts are given in the cell at q = 0; their links' frames there are X_CL(0).
  const std::vector<Eigen::Isometry3d> X_CL = robot.link_poses(Eigen::Vector3d::Zero());
  const std::pair<const char*, const GantryParts::Part*> named[] = {
      {"bridge", &parts.bridge}, {"carriage", &parts.carriage}, {"ram", &parts.ram}};
  std::vector<LinkShape> shapes;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& [link, part] = named[i];
    if (!part->center.allFinite()) throw Error(std::string("gantry ") + link + ": center must be finite");
    const Eigen::Isometry3d X_LG = X_CL[i + 1].inverse() * Eigen::Translation3d(part->center);
    shapes.push_back({link, X_LG, BoxShape{part->half_extents}});
  }
  return robot.with_shapes(std::move(shapes));
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

Robot Robot::with_shapes(std::vector<LinkShape> shapes) const {
  Robot robot = *this;
  robot.shapes_ = std::move(shapes);
  robot.shape_links_.clear();
  for (std::size_t i = 0; i < robot.shapes_.size(); ++i) {
    const LinkShape& shape = robot.shapes_[i];
    const std::string what = "robot shape " + std::to_string(i) + " (link '" + shape.link + "')";
    const auto it = std::find(link_names_.begin(), link_names_.end(), shape.link);
    if (it == link_names_.end()) throw Error(what + ": the robot has no such link");
    validate_shape(shape, what);
    robot.shape_links_.push_back(static_cast<int>(it - link_names_.begin()));
  }
  return robot;
}

std::vector<Eigen::Isometry3d> Robot::shape_poses(const Eigen::VectorXd& q) const {
  const std::vector<Eigen::Isometry3d> X_CL = link_poses(q);
  std::vector<Eigen::Isometry3d> X_CG;
  X_CG.reserve(shapes_.size());
  for (std::size_t i = 0; i < shapes_.size(); ++i) {
    X_CG.push_back(X_CL[static_cast<std::size_t>(shape_links_[i])] * shapes_[i].X_LG);
  }
  return X_CG;
}

std::vector<LinkBox> Robot::shape_boxes() const {
  std::vector<LinkBox> boxes;
  boxes.reserve(shapes_.size());
  for (const LinkShape& shape : shapes_) boxes.push_back(bounding_box(shape));
  return boxes;
}

std::size_t Robot::triangle_count() const {
  std::size_t count = 0;
  for (const LinkShape& shape : shapes_) count += cellmap::triangle_count(shape.geometry);
  return count;
}

}  // namespace cellmap
