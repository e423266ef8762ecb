#include "camera_input.hpp"

#include <thread>

#include "cellmap/common/error.hpp"
#include "cellmap/sensor/replay_source.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::daemon {
namespace {

// Live: 16 s of a 250 Hz controller, far more than a frame waits. A replay loads all its poses at once.
std::size_t pose_capacity(const SourceConfig& config) {
  return std::holds_alternative<ReplayConfig>(config.camera.source) ? 1'000'000 : 4096;
}

}  // namespace

CameraInput::CameraInput(const SourceConfig& config, const dds::Participant& participant,
                         const std::string& cell, transport::OnRefused on_refused)
    : source_(make_depth_source(config.camera)),
      poses_(config.camera.pose_tolerance, pose_capacity(config)),
      assembler_(config.grouping, config.camera.X_ES),
      on_refused_(std::move(on_refused)) {
  transport::InputLimits limits;
  limits.max_stamp_skew = kMaxPoseSkew;
  if (!std::holds_alternative<ReplayConfig>(config.camera.source))
    robot_.emplace(participant, cell, limits, on_refused_);
}

SourceStatus CameraInput::open() {
  const SourceStatus status = source_->open();
  if (const auto* replay = dynamic_cast<const ReplaySource*>(source_.get())) {
    for (const StampedPose& pose : replay->poses()) poses_.push(pose);
    poses_received_ += replay->size();
  }
  return status;
}

std::vector<Sweep> CameraInput::step(std::chrono::milliseconds timeout) {
  if (robot_) {
    for (const transport::RobotState& state : robot_->take()) {
      try {
        poses_.push(static_cast<double>(state.stamp_ns) * 1e-9, state.X_CE);
        ++poses_received_;
      } catch (const Error& e) {
        ++poses_refused_;
        if (on_refused_) on_refused_(std::string(transport::kRobotStateTopic) + ": " + e.what());
      }
    }
  }
  const auto start = std::chrono::steady_clock::now();
  std::optional<Frame> frame = source_->next(timeout);
  const double now = steady_seconds();
  if (frame) assembler_.add(std::move(*frame), now);
  std::vector<Sweep> sweeps = assembler_.poll(poses_, now);
  const SourceState state = source_->status().state;
  if (state != SourceState::kConnected) {
    for (Sweep& sweep : assembler_.flush(poses_)) sweeps.push_back(std::move(sweep));
    // Ended or failed sources return at once: wait out the timeout so the loop never spins.
    if (!frame) std::this_thread::sleep_until(start + timeout);
  }
  return sweeps;
}

std::uint64_t CameraInput::poses_rejected() const {
  return poses_refused_ + (robot_ ? robot_->rejected() : 0);
}

}  // namespace cellmap::daemon
