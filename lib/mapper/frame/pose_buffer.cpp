// SPDX-License-Identifier: Apache-2.0
#include "cellmap/frame/pose_buffer.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

void check_rigid(const Eigen::Isometry3d& X, const std::string& what) {
  if (!X.matrix().allFinite()) throw Error(what + ": pose is not finite");
  const Eigen::Matrix3d R = X.linear();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0) {
    throw Error(what + ": rotation is not orthonormal");
  }
}

bool pose_before(const StampedPose& sample, double stamp) {
  return sample.stamp < stamp;
}

}  // namespace

Eigen::Isometry3d interpolate_pose(const Eigen::Isometry3d& X_a, const Eigen::Isometry3d& X_b, double t) {
  const Eigen::Quaterniond q_a(X_a.linear());
  const Eigen::Quaterniond q_b(X_b.linear());
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q_a.slerp(t, q_b).normalized().toRotationMatrix();  // Eigen's slerp takes the shorter arc
  X.translation() = (1.0 - t) * X_a.translation() + t * X_b.translation();
  return X;
}

PoseBuffer::PoseBuffer(double tolerance, std::size_t capacity) : tolerance_(tolerance), capacity_(capacity) {
  if (!(tolerance > 0) || !std::isfinite(tolerance))
    throw Error("pose buffer: tolerance must be > 0 seconds");
  if (capacity < 2) throw Error("pose buffer: capacity must be at least 2 samples");
}

void PoseBuffer::push(double stamp, const Eigen::Isometry3d& X_CE) {
  if (!std::isfinite(stamp)) throw Error("pose buffer: stamp is not finite");
  check_rigid(X_CE, "pose buffer: sample at " + std::to_string(stamp));
  std::lock_guard<std::mutex> lock(mutex_);
  auto where = std::lower_bound(samples_.begin(), samples_.end(), stamp, pose_before);
  if (where != samples_.end() && where->stamp == stamp) {
    where->X_CE = X_CE;
  } else {
    samples_.insert(where, StampedPose{stamp, X_CE});
  }
  while (samples_.size() > capacity_) samples_.pop_front();
}

PoseBuffer::Result PoseBuffer::at(double stamp) const {
  Result result;
  if (!std::isfinite(stamp)) return result;
  std::lock_guard<std::mutex> lock(mutex_);
  if (samples_.empty() || stamp > samples_.back().stamp) {
    result.status = PoseLookup::kPending;
    return result;
  }
  auto after = std::lower_bound(samples_.begin(), samples_.end(), stamp, pose_before);  // first >= stamp
  if (after->stamp == stamp) {
    result.status = PoseLookup::kFound;
    result.X_CE = after->X_CE;
    return result;
  }
  if (after == samples_.begin()) return result;  // older than every sample
  const StampedPose& a = *(after - 1);
  const StampedPose& b = *after;
  if (stamp - a.stamp > tolerance_ || b.stamp - stamp > tolerance_) return result;
  result.status = PoseLookup::kFound;
  result.X_CE = interpolate_pose(a.X_CE, b.X_CE, (stamp - a.stamp) / (b.stamp - a.stamp));
  return result;
}

std::size_t PoseBuffer::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return samples_.size();
}

SensorPoser::SensorPoser(const Eigen::Isometry3d& X_ES) : X_ES_(X_ES) {
  check_rigid(X_ES, "hand-eye extrinsic X_ES");
}

PoseLookup SensorPoser::attach(Frame& frame, const PoseBuffer& poses) {
  const PoseBuffer::Result pose = poses.at(frame.stamp);
  if (pose.status == PoseLookup::kFound) {
    frame.X_CS = pose.X_CE * X_ES_;
    ++posed_;
  } else if (pose.status == PoseLookup::kMissing) {
    ++dropped_;
  }
  return pose.status;
}

}  // namespace cellmap
