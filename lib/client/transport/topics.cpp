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

}  // namespace cellmap::transport
