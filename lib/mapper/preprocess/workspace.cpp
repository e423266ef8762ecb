// SPDX-License-Identifier: Apache-2.0
#include "cellmap/preprocess/workspace.hpp"

#include <cmath>
#include <sstream>

#include "cellmap/common/error.hpp"
#include "cellmap/robot/robot.hpp"

namespace cellmap {
namespace {

constexpr std::int64_t kKeyBits = 21;  // per axis: ±2^20 voxels
constexpr std::int64_t kKeyOffset = std::int64_t{1} << (kKeyBits - 1);

}  // namespace

Workspace Workspace::box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper) {
  if (!lower.allFinite() || !upper.allFinite() || (lower.array() > upper.array()).any()) {
    std::ostringstream msg;
    msg << "workspace box: need finite lower <= upper, got [" << lower.transpose() << "] .. ["
        << upper.transpose() << "]";
    throw Error(msg.str());
  }
  Workspace w;
  w.bounds_ = {lower, upper};
  return w;
}

Workspace Workspace::from_points(const std::vector<Eigen::Vector3d>& points_C, double envelope,
                                 double voxel) {
  if (points_C.empty()) throw Error("workspace: no sampled points");
  if (!std::isfinite(voxel) || voxel <= 0.0) throw Error("workspace: voxel must be > 0");
  if (!std::isfinite(envelope) || envelope < 0.0) throw Error("workspace: envelope must be >= 0");
  Workspace w;
  w.voxel_ = voxel;
  w.bounds_ = {Eigen::Vector3d::Constant(INFINITY), Eigen::Vector3d::Constant(-INFINITY)};
  // A voxel whose centre is within envelope + half its diagonal of a sample may hold points within envelope.
  const double reach = envelope + 0.5 * std::sqrt(3.0) * voxel;
  const int steps = static_cast<int>(std::ceil(reach / voxel));
  const double limit = static_cast<double>(kKeyOffset - 1) * voxel;
  for (const Eigen::Vector3d& p : points_C) {
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() + reach > limit)
      throw Error("workspace: sample point out of range");
    const Eigen::Vector3d cell = (p / voxel).array().floor();
    for (int dx = -steps; dx <= steps; ++dx) {
      for (int dy = -steps; dy <= steps; ++dy) {
        for (int dz = -steps; dz <= steps; ++dz) {
          const Eigen::Vector3d centre = (cell + Eigen::Vector3d(dx, dy, dz)).array() * voxel + 0.5 * voxel;
          if ((centre - p).norm() > reach) continue;
          w.voxels_.insert(w.key(centre));
          w.bounds_.min = w.bounds_.min.cwiseMin((centre.array() - 0.5 * voxel).matrix());
          w.bounds_.max = w.bounds_.max.cwiseMax((centre.array() + 0.5 * voxel).matrix());
        }
      }
    }
  }
  return w;
}

std::int64_t Workspace::key(const Eigen::Vector3d& p_C) const {
  std::int64_t result = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const auto index = static_cast<std::int64_t>(std::floor(p_C[axis] / voxel_)) + kKeyOffset;
    result = (result << kKeyBits) | (index & ((std::int64_t{1} << kKeyBits) - 1));
  }
  return result;
}

bool Workspace::contains(const Eigen::Vector3d& p_C) const {
  if (!bounds_.contains(p_C)) return false;
  return is_box() || voxels_.count(key(p_C)) > 0;
}

Workspace workspace_from_robot(const Robot& robot, double tool_envelope, int samples, double voxel) {
  if (samples < 2) throw Error("workspace: samples per joint must be >= 2");
  if (!std::isfinite(tool_envelope) || tool_envelope < 0.0)
    throw Error("workspace: tool envelope must be >= 0");
  if (!std::isfinite(voxel) || voxel <= 0.0) throw Error("workspace: voxel must be > 0");
  const int dof = robot.dof();
  bool prismatic_only = true;
  for (const Robot::Step& step : robot.steps()) prismatic_only &= step.type != Robot::JointType::kRevolute;
  const int per_joint = prismatic_only ? 2 : samples;  // corners suffice for an affine map q -> tool position
  const double configurations = std::pow(static_cast<double>(per_joint), dof);
  if (configurations > 1e6) throw Error("workspace: samples^dof exceeds 1e6 configurations");

  std::vector<Eigen::Vector3d> tool_C;
  Eigen::VectorXd q(dof);
  std::vector<int> digit(static_cast<std::size_t>(dof), 0);
  for (long n = 0; n < static_cast<long>(configurations); ++n) {
    for (int j = 0; j < dof; ++j) {
      const JointLimits& limits = robot.limits()[static_cast<std::size_t>(j)];
      q[j] =
          limits.lower + (limits.upper - limits.lower) * digit[static_cast<std::size_t>(j)] / (per_joint - 1);
    }
    tool_C.push_back(robot.tool_pose(q).translation());
    for (int j = 0; j < dof && ++digit[static_cast<std::size_t>(j)] == per_joint; ++j) {
      digit[static_cast<std::size_t>(j)] = 0;
    }
  }
  if (!prismatic_only) return Workspace::from_points(tool_C, tool_envelope, voxel);
  Eigen::Vector3d lower = tool_C.front(), upper = tool_C.front();
  for (const Eigen::Vector3d& p : tool_C) {
    lower = lower.cwiseMin(p);
    upper = upper.cwiseMax(p);
  }
  return Workspace::box(lower.array() - tool_envelope, upper.array() + tool_envelope);
}

std::vector<int> crop_to_workspace(const Cloud& cloud, const Workspace& workspace) {
  std::vector<int> kept;
  kept.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (workspace.contains(cloud[i].getVector3fMap().cast<double>())) kept.push_back(static_cast<int>(i));
  }
  return kept;
}

}  // namespace cellmap
