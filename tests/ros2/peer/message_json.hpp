// SPDX-License-Identifier: Apache-2.0
#pragma once
// ros2_peer's output: one JSON object per line on stdout, flushed at once (a test reads the lines as they
// come). The received messages are printed whole, every field under its ROS name; doubles and floats with 17
// significant digits (a float as the double it converts to exactly), NaN and infinities as the strings "NaN",
// "Infinity" and "-Infinity" (JSON has no such numbers).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "moveit_msgs/msg/CollisionObject.h"
#include "visualization_msgs/msg/MarkerArray.h"

namespace ros2_peer {

/// A JSON text written front to back; commas between members and elements are placed by the writer.
class Json final {
 public:
  Json& begin_object();
  Json& end_object();
  Json& begin_array();
  Json& end_array();
  /// The name of the next member of the current object.
  Json& key(std::string_view name);
  Json& text(std::string_view value);
  Json& real(double value);
  Json& integer(std::int64_t value);
  Json& boolean(bool value);
  [[nodiscard]] const std::string& str() const { return out_; }

 private:
  // Before a value: a comma unless it is the first in its object or array, or follows its key.
  void next_value();
  std::string out_;
  std::vector<bool> empty_;  // per open object or array: nothing in it yet
  bool after_key_ = false;
};

/// Writes `line` and '\n' to stdout and flushes; safe from any thread (readers print from Fast DDS's).
void print_line(const std::string& line);

void write(Json& json, const moveit_msgs::msg::dds_::CollisionObject_& message);
void write(Json& json, const visualization_msgs::msg::dds_::MarkerArray_& message);

}  // namespace ros2_peer
