// SPDX-License-Identifier: Apache-2.0
#include "message_json.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <mutex>

namespace ros2_peer {

Json& Json::begin_object() {
  next_value();
  out_ += '{';
  empty_.push_back(true);
  return *this;
}

Json& Json::end_object() {
  out_ += '}';
  empty_.pop_back();
  return *this;
}

Json& Json::begin_array() {
  next_value();
  out_ += '[';
  empty_.push_back(true);
  return *this;
}

Json& Json::end_array() {
  out_ += ']';
  empty_.pop_back();
  return *this;
}

Json& Json::key(std::string_view name) {
  text(name);
  out_ += ':';
  after_key_ = true;
  return *this;
}

Json& Json::text(std::string_view value) {
  next_value();
  out_ += '"';
  for (const char c : value) {
    switch (c) {
      case '"':
        out_ += "\\\"";
        break;
      case '\\':
        out_ += "\\\\";
        break;
      case '\n':
        out_ += "\\n";
        break;
      case '\r':
        out_ += "\\r";
        break;
      case '\t':
        out_ += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
          out_ += escaped;
        } else {
          out_ += c;  // bytes >= 0x80 pass as they are: UTF-8 stays UTF-8
        }
    }
  }
  out_ += '"';
  return *this;
}

Json& Json::real(double value) {
  if (std::isnan(value)) return text("NaN");
  if (std::isinf(value)) return text(value > 0 ? "Infinity" : "-Infinity");
  next_value();
  // 17 significant digits give back the very double, so tests can compare exactly.
  char digits[32];
  std::snprintf(digits, sizeof digits, "%.17g", value);
  out_ += digits;
  return *this;
}

Json& Json::integer(std::int64_t value) {
  next_value();
  out_ += std::to_string(value);
  return *this;
}

Json& Json::boolean(bool value) {
  next_value();
  out_ += value ? "true" : "false";
  return *this;
}

void Json::next_value() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (empty_.empty()) return;
  if (!empty_.back()) out_ += ',';
  empty_.back() = false;
}

void print_line(const std::string& line) {
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  std::fwrite(line.data(), 1, line.size(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

namespace {

using builtin_interfaces::msg::dds_::Duration_;
using builtin_interfaces::msg::dds_::Time_;
using geometry_msgs::msg::dds_::Point32_;
using geometry_msgs::msg::dds_::Point_;
using geometry_msgs::msg::dds_::Polygon_;
using geometry_msgs::msg::dds_::Pose_;
using geometry_msgs::msg::dds_::Quaternion_;
using geometry_msgs::msg::dds_::Vector3_;
using object_recognition_msgs::msg::dds_::ObjectType_;
using sensor_msgs::msg::dds_::CompressedImage_;
using shape_msgs::msg::dds_::Mesh_;
using shape_msgs::msg::dds_::MeshTriangle_;
using shape_msgs::msg::dds_::Plane_;
using shape_msgs::msg::dds_::SolidPrimitive_;
using std_msgs::msg::dds_::ColorRGBA_;
using std_msgs::msg::dds_::Header_;
using visualization_msgs::msg::dds_::Marker_;
using visualization_msgs::msg::dds_::MeshFile_;
using visualization_msgs::msg::dds_::UVCoordinate_;

// One overload per IDL type; the sequence and array templates below call them, so all are declared first.
void value(Json& json, bool v) {
  json.boolean(v);
}
void value(Json& json, std::uint8_t v) {
  json.integer(v);
}
void value(Json& json, std::int32_t v) {
  json.integer(v);
}
void value(Json& json, std::uint32_t v) {
  json.integer(v);
}
void value(Json& json, float v) {
  json.real(v);
}
void value(Json& json, double v) {
  json.real(v);
}
void value(Json& json, const std::string& v) {
  json.text(v);
}
void value(Json& json, const Time_& v);
void value(Json& json, const Duration_& v);
void value(Json& json, const Header_& v);
void value(Json& json, const Point_& v);
void value(Json& json, const Point32_& v);
void value(Json& json, const Quaternion_& v);
void value(Json& json, const Pose_& v);
void value(Json& json, const Vector3_& v);
void value(Json& json, const Polygon_& v);
void value(Json& json, const ColorRGBA_& v);
void value(Json& json, const ObjectType_& v);
void value(Json& json, const SolidPrimitive_& v);
void value(Json& json, const MeshTriangle_& v);
void value(Json& json, const Mesh_& v);
void value(Json& json, const Plane_& v);
void value(Json& json, const CompressedImage_& v);
void value(Json& json, const UVCoordinate_& v);
void value(Json& json, const MeshFile_& v);
void value(Json& json, const Marker_& v);

template <typename T>
void value(Json& json, const std::vector<T>& items) {
  json.begin_array();
  for (const T& item : items) value(json, item);
  json.end_array();
}

template <typename T, std::size_t N>
void value(Json& json, const std::array<T, N>& items) {
  json.begin_array();
  for (const T& item : items) value(json, item);
  json.end_array();
}

template <typename T>
void member(Json& json, std::string_view name, const T& v) {
  json.key(name);
  value(json, v);
}

void value(Json& json, const Time_& v) {
  json.begin_object();
  member(json, "sec", v.sec());
  member(json, "nanosec", v.nanosec());
  json.end_object();
}

void value(Json& json, const Duration_& v) {
  json.begin_object();
  member(json, "sec", v.sec());
  member(json, "nanosec", v.nanosec());
  json.end_object();
}

void value(Json& json, const Header_& v) {
  json.begin_object();
  member(json, "stamp", v.stamp());
  member(json, "frame_id", v.frame_id());
  json.end_object();
}

void value(Json& json, const Point_& v) {
  json.begin_object();
  member(json, "x", v.x());
  member(json, "y", v.y());
  member(json, "z", v.z());
  json.end_object();
}

void value(Json& json, const Point32_& v) {
  json.begin_object();
  member(json, "x", v.x());
  member(json, "y", v.y());
  member(json, "z", v.z());
  json.end_object();
}

void value(Json& json, const Quaternion_& v) {
  json.begin_object();
  member(json, "x", v.x());
  member(json, "y", v.y());
  member(json, "z", v.z());
  member(json, "w", v.w());
  json.end_object();
}

void value(Json& json, const Pose_& v) {
  json.begin_object();
  member(json, "position", v.position());
  member(json, "orientation", v.orientation());
  json.end_object();
}

void value(Json& json, const Vector3_& v) {
  json.begin_object();
  member(json, "x", v.x());
  member(json, "y", v.y());
  member(json, "z", v.z());
  json.end_object();
}

void value(Json& json, const Polygon_& v) {
  json.begin_object();
  member(json, "points", v.points());
  json.end_object();
}

void value(Json& json, const ColorRGBA_& v) {
  json.begin_object();
  member(json, "r", v.r());
  member(json, "g", v.g());
  member(json, "b", v.b());
  member(json, "a", v.a());
  json.end_object();
}

void value(Json& json, const ObjectType_& v) {
  json.begin_object();
  member(json, "key", v.key());
  member(json, "db", v.db());
  json.end_object();
}

void value(Json& json, const SolidPrimitive_& v) {
  json.begin_object();
  member(json, "type", v.type());
  member(json, "dimensions", v.dimensions());
  member(json, "polygon", v.polygon());
  json.end_object();
}

void value(Json& json, const MeshTriangle_& v) {
  json.begin_object();
  member(json, "vertex_indices", v.vertex_indices());
  json.end_object();
}

void value(Json& json, const Mesh_& v) {
  json.begin_object();
  member(json, "triangles", v.triangles());
  member(json, "vertices", v.vertices());
  json.end_object();
}

void value(Json& json, const Plane_& v) {
  json.begin_object();
  member(json, "coef", v.coef());
  json.end_object();
}

void value(Json& json, const CompressedImage_& v) {
  json.begin_object();
  member(json, "header", v.header());
  member(json, "format", v.format());
  member(json, "data", v.data());
  json.end_object();
}

void value(Json& json, const UVCoordinate_& v) {
  json.begin_object();
  member(json, "u", v.u());
  member(json, "v", v.v());
  json.end_object();
}

void value(Json& json, const MeshFile_& v) {
  json.begin_object();
  member(json, "filename", v.filename());
  member(json, "data", v.data());
  json.end_object();
}

void value(Json& json, const Marker_& v) {
  json.begin_object();
  member(json, "header", v.header());
  member(json, "ns", v.ns());
  member(json, "id", v.id());
  member(json, "type", v.type());
  member(json, "action", v.action());
  member(json, "pose", v.pose());
  member(json, "scale", v.scale());
  member(json, "color", v.color());
  member(json, "lifetime", v.lifetime());
  member(json, "frame_locked", v.frame_locked());
  member(json, "points", v.points());
  member(json, "colors", v.colors());
  member(json, "texture_resource", v.texture_resource());
  member(json, "texture", v.texture());
  member(json, "uv_coordinates", v.uv_coordinates());
  member(json, "text", v.text());
  member(json, "mesh_resource", v.mesh_resource());
  member(json, "mesh_file", v.mesh_file());
  member(json, "mesh_use_embedded_materials", v.mesh_use_embedded_materials());
  json.end_object();
}

}  // namespace

void write(Json& json, const moveit_msgs::msg::dds_::CollisionObject_& message) {
  json.begin_object();
  member(json, "header", message.header());
  member(json, "pose", message.pose());
  member(json, "id", message.id());
  member(json, "type", message.type());
  member(json, "primitives", message.primitives());
  member(json, "primitive_poses", message.primitive_poses());
  member(json, "meshes", message.meshes());
  member(json, "mesh_poses", message.mesh_poses());
  member(json, "planes", message.planes());
  member(json, "plane_poses", message.plane_poses());
  member(json, "subframe_names", message.subframe_names());
  member(json, "subframe_poses", message.subframe_poses());
  member(json, "operation", message.operation());
  json.end_object();
}

void write(Json& json, const visualization_msgs::msg::dds_::MarkerArray_& message) {
  json.begin_object();
  member(json, "markers", message.markers());
  json.end_object();
}

}  // namespace ros2_peer
