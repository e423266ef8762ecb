// SPDX-License-Identifier: Apache-2.0
#include "cellmap/ros2/type_hash.hpp"

#include "cellmap/common/error.hpp"
#include "ros2/ros2_type_hashes.h"  // generated from idl/ros2 (idl/CMakeLists.txt)

namespace cellmap::ros2 {

std::string type_hash(std::string_view ros_type) {
  // A few dozen rows, looked up once per endpoint: a scan is all it takes.
  for (const generated::TypeHashRow& row : generated::kTypeHashes) {
    if (ros_type == row.ros_type) return row.hash;
  }
  throw Error("ROS 2 type '" + std::string(ros_type) + "' has no type hash: idl/ros2 does not define it");
}

std::string type_hash_user_data(std::string_view ros_type) {
  return "typehash=" + type_hash(ros_type) + ";";
}

}  // namespace cellmap::ros2
