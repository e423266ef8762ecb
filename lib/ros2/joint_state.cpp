// SPDX-License-Identifier: Apache-2.0
#include "cellmap/ros2/joint_state.hpp"

#include <cmath>
#include <unordered_map>

#include "cellmap/common/error.hpp"
#include "quoted.hpp"

namespace cellmap::ros2 {

std::vector<double> in_robot_order(const std::vector<std::string>& names,
                                   const std::vector<double>& positions,
                                   const std::vector<std::string>& robot_joints) {
  if (names.size() > kMaxJointStateNames)
    throw Error(std::to_string(names.size()) + " names, more than " + std::to_string(kMaxJointStateNames));
  if (names.size() != positions.size()) {
    throw Error(std::to_string(names.size()) + " names but " + std::to_string(positions.size()) +
                " positions");
  }
  std::unordered_map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!index.emplace(names[i], i).second) throw Error("joint " + quoted(names[i]) + " given twice");
  }
  std::vector<double> ordered;
  ordered.reserve(robot_joints.size());
  for (const std::string& joint : robot_joints) {
    const auto it = index.find(joint);
    if (it == index.end()) throw Error("no position for joint " + quoted(joint));
    const double q = positions[it->second];
    if (!std::isfinite(q)) throw Error("joint " + quoted(joint) + " position is not finite");
    ordered.push_back(q);
  }
  return ordered;
}

}  // namespace cellmap::ros2
