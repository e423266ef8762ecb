// SPDX-License-Identifier: Apache-2.0
#include "ros2_outputs.hpp"

#include <spdlog/spdlog.h>

#include "cellmap/common/error.hpp"

namespace cellmap::daemon {
namespace {

std::string describe_output(const char* what, const ros2::TopicOutput& output) {
  return std::string(what) + " on " + output.topic + " (frame " + output.frame_id +
         (output.unknown_boxes ? ", unknown space too" : ", obstacles only") + ")";
}

}  // namespace

Ros2Outputs::Ros2Outputs(const Ros2Config& config, const dds::Participant& participant) {
  if (config.collision_objects) {
    collision_objects_.emplace(participant, *config.collision_objects);
    description_ = describe_output("MoveIt collision objects", *config.collision_objects);
  }
  if (config.markers) {
    markers_.emplace(participant, *config.markers);
    description_ += (description_.empty() ? "" : ", ") + describe_output("RViz markers", *config.markers);
  }
}

void Ros2Outputs::publish(const Environment& env, const EnvironmentDelta& delta) {
  try {
    if (collision_objects_) collision_objects_->write(env, delta);
  } catch (const Error& e) {
    report("collision objects", e);
  }
  try {
    if (markers_) markers_->write(env);
  } catch (const Error& e) {
    report("markers", e);
  }
}

void Ros2Outputs::serve_new_readers() {
  try {
    if (collision_objects_ && collision_objects_->resend_if_new_readers())
      spdlog::info("ROS 2: a MoveIt reader joined; sent it the environment ({} readers)",
                   collision_objects_->readers());
  } catch (const Error& e) {
    report("collision objects", e);
  }
}

std::string Ros2Outputs::describe() const {
  return description_;
}

void Ros2Outputs::report(const char* what, const Error& e) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (last_fault_ == e.what()) return;
  last_fault_ = e.what();
  spdlog::warn("ROS 2 {} not written: {}", what, e.what());
}

}  // namespace cellmap::daemon
