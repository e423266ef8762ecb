// SPDX-License-Identifier: Apache-2.0
#include "cellmap/ros2/topics.hpp"

#include <cctype>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"

namespace cellmap::ros2 {
namespace {

// Why `name` is not a fully qualified ROS 2 topic name, or "" if it is one.
std::string fault_of(const std::string& name) {
  if (name.empty() || name.front() != '/') return "it must start with '/'";
  if (name.size() == 1 || name.back() == '/') return "it must not end with '/'";
  for (std::size_t i = 1; i < name.size(); ++i) {
    const char c = name[i];
    if (c == '/' && name[i - 1] == '/') return "it has an empty token ('//')";
    if (c != '/' && c != '_' && !std::isalnum(static_cast<unsigned char>(c)))
      return "only letters, digits, '_' and '/' are allowed";
    if (std::isdigit(static_cast<unsigned char>(c)) && name[i - 1] == '/')
      return "a token must not start with a digit";
  }
  return "";
}

}  // namespace

std::string dds_topic(const std::string& ros_topic) {
  const std::string fault = fault_of(ros_topic);
  if (!fault.empty()) throw Error("'" + single_line(ros_topic) + "' is not a ROS 2 topic name: " + fault);
  return "rt" + ros_topic;
}

const char* to_string(Reliability reliability) {
  return reliability == Reliability::kReliable ? "reliable" : "best_effort";
}

}  // namespace cellmap::ros2
