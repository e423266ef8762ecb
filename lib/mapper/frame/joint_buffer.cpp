// SPDX-License-Identifier: Apache-2.0
#include "cellmap/frame/joint_buffer.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

void check_payload(const Payload& payload, const std::string& what) {
  if (!payload.X_EB.matrix().allFinite() || !payload.half_extents.allFinite()) {
    throw Error(what + ": payload is not finite");
  }
  if (payload.half_extents.minCoeff() < 0) throw Error(what + ": payload half extents must be >= 0");
  const Eigen::Matrix3d R = payload.X_EB.linear();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0) {
    throw Error(what + ": payload rotation is not orthonormal");
  }
}

bool joints_before(const JointState& sample, double stamp) {
  return sample.stamp < stamp;
}

}  // namespace

JointBuffer::JointBuffer(Robot robot, double tolerance, std::size_t capacity)
    : robot_(std::move(robot)), tolerance_(tolerance), capacity_(capacity) {
  if (!(tolerance > 0) || !std::isfinite(tolerance))
    throw Error("joint buffer: tolerance must be > 0 seconds");
  if (capacity < 2) throw Error("joint buffer: capacity must be at least 2 samples");
}

void JointBuffer::push(const JointState& sample) {
  const std::string what = "joint buffer: sample at " + std::to_string(sample.stamp);
  if (!std::isfinite(sample.stamp)) throw Error("joint buffer: stamp is not finite");
  if (sample.q.size() != robot_.dof() || !sample.q.allFinite()) {
    throw Error(what + ": needs " + std::to_string(robot_.dof()) + " finite joint positions");
  }
  if (sample.payload) check_payload(*sample.payload, what);
  std::lock_guard<std::mutex> lock(mutex_);
  auto where = std::lower_bound(samples_.begin(), samples_.end(), sample.stamp, joints_before);
  if (where != samples_.end() && where->stamp == sample.stamp) {
    *where = sample;
  } else {
    samples_.insert(where, sample);
  }
  while (samples_.size() > capacity_) samples_.pop_front();
}

JointBuffer::Result JointBuffer::at(double stamp) const {
  Result result;
  if (!std::isfinite(stamp)) return result;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (samples_.empty() || stamp > samples_.back().stamp) {
      result.status = PoseLookup::kPending;
      return result;
    }
    auto after = std::lower_bound(samples_.begin(), samples_.end(), stamp, joints_before);  // first >= stamp
    if (after->stamp == stamp) {
      result.state = *after;
    } else {
      if (after == samples_.begin()) return result;  // older than every sample
      const JointState& a = *(after - 1);
      const JointState& b = *after;
      if (stamp - a.stamp > tolerance_ || b.stamp - stamp > tolerance_) return result;
      const double t = (stamp - a.stamp) / (b.stamp - a.stamp);
      result.state.stamp = stamp;
      result.state.q = (1.0 - t) * a.q + t * b.q;
      result.state.payload = t <= 0.5 ? a.payload : b.payload;
    }
  }
  result.status = PoseLookup::kFound;
  result.X_CL = robot_.link_poses(result.state.q);
  return result;
}

std::size_t JointBuffer::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return samples_.size();
}

}  // namespace cellmap
