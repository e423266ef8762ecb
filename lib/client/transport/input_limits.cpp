// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/input_limits.hpp"

#include <cmath>
#include <sstream>

#include "cellmap/common/error.hpp"
#include "cellmap/transport/topics.hpp"
#include "wire.hpp"

namespace cellmap::transport {
namespace {

std::string text(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out << v.x() << ", " << v.y() << ", " << v.z();
  return out.str();
}

void require_inside(const Eigen::Vector3d& p_C, const InputLimits& limits, const std::string& where) {
  if (!limits.cell.contains(p_C)) {
    throw Error(where + ": (" + text(p_C) + ") is outside the cell [" + text(limits.cell.min()) + "] - [" +
                text(limits.cell.max()) + "]");
  }
}

void require_stamp_near(std::int64_t stamp_ns, const InputLimits& limits, std::int64_t now_ns,
                        const std::string& where) {
  if (limits.max_stamp_skew.count() <= 0) return;
  // In double: an attacker's stamp near INT64_MIN must not overflow the difference.
  const double skew_s = (static_cast<double>(stamp_ns) - static_cast<double>(now_ns)) * 1e-9;
  if (std::abs(skew_s) > std::chrono::duration<double>(limits.max_stamp_skew).count()) {
    throw Error(where + ": stamp_ns: " + std::to_string(skew_s) + " s from now (limit ±" +
                std::to_string(std::chrono::duration<double>(limits.max_stamp_skew).count()) + " s)");
  }
}

}  // namespace

void require_at_most(std::size_t count, std::size_t limit, const std::string& what,
                     const std::string& where) {
  if (count > limit) {
    throw Error(where + ": " + std::to_string(count) + " " + what + ", more than the " +
                std::to_string(limit) + " a sample may carry");
  }
}

void check_limits(const SceneEdit& edit, const InputLimits& limits) {
  const std::string where = wire::edit_name(edit.name);
  if (edit.name.size() > kMaxNameLength)
    throw Error(where + ": name: longer than " + std::to_string(kMaxNameLength) + " bytes");
  if (edit.kind == SceneEdit::Kind::kRemove) return;
  require_inside(edit.center, limits, where + ": center");
  if (edit.kind != SceneEdit::Kind::kAddBox) return;
  const double largest = 0.5 * limits.cell.sizes().maxCoeff();
  if (!(edit.half_extents.minCoeff() > 0.0) || edit.half_extents.maxCoeff() > largest) {
    throw Error(where + ": half_extents: (" + text(edit.half_extents) + ") must be positive and at most " +
                std::to_string(largest) + " (half the cell's largest side)");
  }
  if (std::abs(edit.yaw) > 2 * M_PI)
    throw Error(where + ": yaw: " + std::to_string(edit.yaw) + " is beyond ±2π");
}

void check_limits(const RobotState& state, const InputLimits& limits, std::int64_t now_ns) {
  const std::string where = wire::sample_name(kRobotStateTopic, state.cell, state.stamp_ns);
  require_inside(state.X_CE.translation(), limits, where + ": position");
  require_stamp_near(state.stamp_ns, limits, now_ns, where);
}

void check_limits(const RobotJoints& joints, const InputLimits& limits, std::int64_t now_ns) {
  const std::string where = wire::sample_name(kRobotJointsTopic, joints.cell, joints.stamp_ns);
  require_stamp_near(joints.stamp_ns, limits, now_ns, where);
  if (!joints.payload) return;
  const double largest = limits.cell.sizes().maxCoeff();
  if (joints.payload->X_EB.translation().norm() > largest ||
      joints.payload->half_extents.maxCoeff() > largest / 2) {
    throw Error(where + ": payload: centre (" + text(joints.payload->X_EB.translation()) +
                ") or half extents (" + text(joints.payload->half_extents) + ") do not fit in the cell");
  }
}

}  // namespace cellmap::transport
