// SPDX-License-Identifier: Apache-2.0
#include "camera_input.hpp"

#include <limits>
#include <thread>

#include "cellmap/common/error.hpp"
#include "cellmap/ros2/sensor_sources.hpp"
#include "cellmap/sensor/replay_source.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::daemon {
namespace {

// 16 s of a 250 Hz controller, far more than a frame waits.
constexpr std::size_t kLiveSamples = 4096;

transport::InputLimits skew_limits() {
  transport::InputLimits limits;
  limits.max_stamp_skew = kMaxPoseSkew;
  return limits;
}

}  // namespace

RobotInput::RobotInput(const std::optional<Robot>& robot, double tolerance,
                       const dds::Participant& participant, const std::string& cell,
                       const std::string& joint_states, transport::OnRefused on_refused)
    : on_refused_(std::move(on_refused)) {
  if (!joint_states.empty() && !robot)
    throw Error("ros2.joint_states " + joint_states + " needs a robot model (a `robot` section) to pose");
  if (robot) {
    joints_.emplace(*robot, tolerance, kLiveSamples);
    if (joint_states.empty()) {
      joint_reader_.emplace(participant, cell, robot->joint_names(), skew_limits(), on_refused_);
    } else {
      joint_state_reader_.emplace(participant, joint_states, cell, robot->joint_names(), kMaxPoseSkew,
                                  on_refused_);
    }
  } else {
    poses_.emplace(tolerance, kLiveSamples);
    pose_reader_.emplace(participant, cell, skew_limits(), on_refused_);
  }
}

void RobotInput::pump(std::chrono::milliseconds timeout) {
  const auto refuse = [this](const char* topic, const Error& e) {
    ++refused_;
    if (on_refused_) on_refused_(std::string(topic) + ": " + e.what());
  };
  if (joints_) {
    const char* topic = joint_reader_ ? transport::kRobotJointsTopic : joint_state_reader_->topic().c_str();
    for (const transport::RobotJoints& sample :
         joint_reader_ ? joint_reader_->take(timeout) : joint_state_reader_->take(timeout)) {
      try {
        joints_->push(sample.state());
        ++received_;
      } catch (const Error& e) {
        refuse(topic, e);
      }
    }
    return;
  }
  for (const transport::RobotState& state : pose_reader_->take(timeout)) {
    try {
      poses_->push(static_cast<double>(state.stamp_ns) * 1e-9, state.X_CE);
      ++received_;
    } catch (const Error& e) {
      refuse(transport::kRobotStateTopic, e);
    }
  }
}

std::uint64_t RobotInput::rejected() const {
  if (joint_state_reader_) return refused_ + joint_state_reader_->rejected();
  return refused_ + (joint_reader_ ? joint_reader_->rejected() : pose_reader_->rejected());
}

std::unique_ptr<DepthSource> make_source(const SourceConfig& config, const dds::Participant& participant,
                                         transport::OnRefused on_refused) {
  ros2::TopicInput input = config.ros2;
  input.max_stamp_skew = kMaxPoseSkew;
  if (config.kind == SourceKind::kPointCloud2)
    return ros2::make_point_cloud2_source(participant, config.sensor, input, std::move(on_refused));
  if (config.kind == SourceKind::kLaserScan)
    return ros2::make_laser_scan_source(participant, config.sensor, input, std::move(on_refused));
  return make_depth_source(config.camera);
}

CameraInput::CameraInput(const SourceConfig& config, std::unique_ptr<DepthSource> source,
                         const RobotInput* robot)
    : config_(config), source_(std::move(source)), robot_(robot) {
  config_.grouping.validate();
  if (std::holds_alternative<ReplayConfig>(config.camera.source)) {
    recorded_.emplace(config.camera.pose_tolerance, 1'000'000);
    robot_ = nullptr;
  }
}

SourceStatus CameraInput::open() {
  const SourceStatus status = source_->open();
  if (const auto* replay = dynamic_cast<const ReplaySource*>(source_.get())) {
    for (const StampedPose& pose : replay->poses()) recorded_->push(pose);
  }
  return status;
}

std::vector<SweepFrame> CameraInput::step(std::chrono::milliseconds timeout) {
  const auto start = std::chrono::steady_clock::now();
  std::optional<Frame> frame = source_->next(timeout);
  if (frame) {
    // Only the points and the intrinsics (for the self filter) travel on, the image only for the pixels
    // without a return (no_return_range); a 640x480 image is 600 kB.
    if (frame->depth && !(config_.no_return_range > 0.0)) frame->depth->depth = {};
    waiting_.push_back(Waiting{std::move(*frame), steady_seconds()});
  }
  std::vector<SweepFrame> posed;
  const bool streaming = source_->status().state == SourceState::kConnected;
  pose_waiting(
      streaming ? steady_seconds() - config_.grouping.pose_wait : std::numeric_limits<double>::infinity(),
      posed);
  // Ended or failed sources return at once: wait out the timeout so the loop never spins.
  if (!streaming && !frame) std::this_thread::sleep_until(start + timeout);
  return posed;
}

PoseLookup CameraInput::locate(SweepFrame& f) const {
  const double stamp = f.frame.stamp;
  std::optional<Eigen::Isometry3d> X_CE;
  if (robot_ && robot_->joints()) {
    const JointBuffer::Result r = robot_->joints()->at(stamp);
    if (r.status != PoseLookup::kFound) return r.status;
    f.robot = RobotAt{r.X_CL, r.state.payload};
    X_CE = r.X_CE();
  } else if (config_.mount == sim::Mount::kTool) {
    const PoseBuffer* poses = recorded_ ? &*recorded_ : robot_->poses();
    const PoseBuffer::Result r = poses->at(stamp);
    if (r.status != PoseLookup::kFound) return r.status;
    X_CE = r.X_CE;
  }
  f.frame.X_CS = config_.mount == sim::Mount::kCell ? config_.X_CS : *X_CE * config_.camera.X_ES;
  return PoseLookup::kFound;
}

void CameraInput::pose_waiting(double give_up_before, std::vector<SweepFrame>& posed) {
  while (!waiting_.empty()) {
    Waiting& head = waiting_.front();
    SweepFrame f{std::move(head.frame), std::nullopt, config_.no_return_range};
    const PoseLookup found = locate(f);
    if (found == PoseLookup::kPending && head.arrived > give_up_before) {
      // Frames behind the head are newer: they wait too.
      head.frame = std::move(f.frame);
      return;
    }
    if (found == PoseLookup::kFound) {
      posed.push_back(std::move(f));
    } else {
      ++dropped_;
    }
    waiting_.pop_front();
  }
}

}  // namespace cellmap::daemon
