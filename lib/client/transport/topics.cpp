// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/topics.hpp"

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"

namespace cellmap::transport {

std::string cell_partition(const std::string& cell) {
  if (cell == kEveryCell) return std::string(kPartitionPrefix) + kEveryCell;
  if (cell.empty()) throw Error("a cell id must not be empty");
  if (cell.find_first_of("*?\\") != std::string::npos)
    throw Error("cell id '" + single_line(cell) + "': '*', '?' and '\\' are DDS partition patterns");
  return kPartitionPrefix + cell;
}

std::string one_cell(std::string cell, const std::string& what) {
  if (cell.empty()) throw Error(what + ": the cell id must not be empty");
  if (cell == kEveryCell) throw Error(what + ": is for one cell, not every cell");
  return cell;
}

std::string default_cell(const dds::Participant& participant) {
  return participant.credentials() ? participant.credentials()->cell : std::string(kEveryCell);
}

dds::Qos in_cell(dds::Qos qos, const std::string& cell) {
  qos.partition(cell_partition(cell));
  return qos;
}

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
  return dds::Qos::make(false, 0).max_samples(kMaxQueuedSceneEdits);
}

dds::Qos robot_state_qos() {
  return dds::Qos::make(false, 256);
}

dds::Qos layer_qos() {
  return dds::Qos::make(false, 1);
}

std::map<security::Role, security::TopicGrants> role_grants(const std::string& cell) {
  using security::Role;
  const std::vector<std::string> partition{cell_partition(one_cell(cell, "DDS Security grants"))};
  const std::vector<std::string> environment{kEnvironmentTopic, kEnvironmentDeltaTopic, kStatusTopic};
  std::vector<std::string> environment_and_layers = environment;
  environment_and_layers.insert(environment_and_layers.end(), {kVoxelLayerTopic, kChangeRegionLayerTopic,
                                                               kSensorLayerTopic, kRobotLayerTopic});
  return {{Role::kDaemon,
           {environment_and_layers, {kRobotStateTopic, kRobotJointsTopic, kSceneEditTopic}, partition}},
          {Role::kPlanner, {{}, environment_and_layers, partition}},
          {Role::kRobot, {{kRobotStateTopic, kRobotJointsTopic}, {}, partition}},
          {Role::kTool, {{kSceneEditTopic}, environment, partition}}};
}

dds::Qos robot_joints_qos() {
  return robot_state_qos();
}

}  // namespace cellmap::transport
