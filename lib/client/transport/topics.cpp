#include "cellmap/transport/topics.hpp"

#include "cellmap/common/error.hpp"

namespace cellmap::transport {

dds::Qos environment_qos() {
  return dds::Qos::make(true, 1);
}

dds::Qos environment_delta_qos(std::uint32_t depth) {
  if (depth == 0) throw Error(std::string(kEnvironmentDeltaTopic) + ": delta depth must be at least 1");
  return dds::Qos::make(true, depth);
}

dds::Qos status_qos() {
  return dds::Qos::make(true, 1);
}

dds::Qos scene_edit_qos() {
  return dds::Qos::make(false, 0);
}

dds::Qos robot_state_qos() {
  return dds::Qos::make(false, 256);
}

dds::Qos layer_qos() {
  return dds::Qos::make(false, 1);
}

std::map<security::Role, security::TopicGrants> role_grants() {
  using security::Role;
  const std::vector<std::string> environment{kEnvironmentTopic, kEnvironmentDeltaTopic, kStatusTopic};
  std::vector<std::string> environment_and_layers = environment;
  environment_and_layers.insert(environment_and_layers.end(),
                                {kVoxelLayerTopic, kChangeRegionLayerTopic, kSensorLayerTopic, kRobotLayerTopic});
  return {{Role::kDaemon, {environment_and_layers, {kRobotStateTopic, kRobotJointsTopic, kSceneEditTopic}}},
          {Role::kPlanner, {{}, environment_and_layers}},
          {Role::kRobot, {{kRobotStateTopic, kRobotJointsTopic}, {}}},
          {Role::kTool, {{kSceneEditTopic}, environment}}};
}

dds::Qos robot_joints_qos() {
  return robot_state_qos();
}

}  // namespace cellmap::transport
