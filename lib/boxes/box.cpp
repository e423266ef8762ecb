// SPDX-License-Identifier: Apache-2.0
#include "cellmap/boxes/box.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"

namespace cellmap {
namespace {

using nlohmann::json;

json vector_json(const Eigen::Vector3d& v) {
  return json::array({v.x(), v.y(), v.z()});
}

class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& where, const std::string& reason) const {
    throw Error(source_ + ": " + where + ": " + reason);
  }

  const json& field(const json& object, const char* key, const std::string& where) const {
    if (!object.is_object()) fail(where, "must be an object");
    const auto it = object.find(key);
    if (it == object.end()) fail(where + "." + key, "is missing");
    return *it;
  }

  double finite(const json& value, const std::string& where) const {
    if (!value.is_number()) fail(where, "must be a number");
    const double x = value.get<double>();
    if (!std::isfinite(x)) fail(where, "must be finite");
    return x;
  }

  std::uint64_t count(const json& value, const std::string& where) const {
    if (!value.is_number_unsigned() && !(value.is_number_integer() && value.get<std::int64_t>() >= 0)) {
      fail(where, "must be a non-negative integer");
    }
    return value.get<std::uint64_t>();
  }

  template <int N>
  Eigen::Matrix<double, N, 1> numbers(const json& value, const std::string& where) const {
    if (!value.is_array() || value.size() != N)
      fail(where, "must be an array of " + std::to_string(N) + " numbers");
    Eigen::Matrix<double, N, 1> out;
    for (int i = 0; i < N; ++i) out[i] = finite(value[i], where + "[" + std::to_string(i) + "]");
    return out;
  }

  BoxSpace space(const json& value, const std::string& where) const {
    if (value == "occupied") return BoxSpace::kOccupied;
    if (value == "unknown") return BoxSpace::kUnknown;
    fail(where, "must be \"occupied\" or \"unknown\"");
  }

 private:
  std::string source_;
};

}  // namespace

bool Box::contains(const Eigen::Vector3d& p_C, double tolerance) const {
  const Eigen::Vector3d p_B = rotation.conjugate() * (p_C - center);
  return (p_B.cwiseAbs() - half_extents).maxCoeff() <= tolerance;
}

bool Box::is_axis_aligned() const {
  return rotation.angularDistance(Eigen::Quaterniond::Identity()) == 0.0;
}

const char* space_name(BoxSpace space) {
  return space == BoxSpace::kUnknown ? "unknown" : "occupied";
}

std::string to_json(const BoxSet& set) {
  json boxes = json::array();
  for (const Box& box : set.boxes) {
    const Eigen::Quaterniond& q = box.rotation;
    json item = {{"id", box.id},
                 {"center", vector_json(box.center)},
                 {"half_extents", vector_json(box.half_extents)},
                 {"rotation", json::array({q.w(), q.x(), q.y(), q.z()})},
                 {"points", box.points}};
    if (box.space != BoxSpace::kOccupied) item["space"] = space_name(box.space);
    boxes.push_back(std::move(item));
  }
  json doc = {{"version", set.version}, {"frame", set.frame}, {"boxes", boxes}};
  return doc.dump(1) + "\n";
}

BoxSet box_set_from_json(const std::string& text, const std::string& source) {
  const Reader reader(source);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for numbers beyond a double
    throw Error(source + ": not valid JSON (" + single_line(e.what()) + ")");
  }
  BoxSet set;
  set.version = reader.count(reader.field(doc, "version", "document"), "version");
  const json& frame = reader.field(doc, "frame", "document");
  if (!frame.is_string()) reader.fail("frame", "must be a string");
  set.frame = frame.get<std::string>();
  const json& boxes = reader.field(doc, "boxes", "document");
  if (!boxes.is_array()) reader.fail("boxes", "must be an array");
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const std::string where = "boxes[" + std::to_string(i) + "]";
    const json& item = boxes[i];
    Box box;
    box.id = reader.count(reader.field(item, "id", where), where + ".id");
    box.center = reader.numbers<3>(reader.field(item, "center", where), where + ".center");
    box.half_extents = reader.numbers<3>(reader.field(item, "half_extents", where), where + ".half_extents");
    if (box.half_extents.minCoeff() < 0) reader.fail(where + ".half_extents", "must not be negative");
    const Eigen::Vector4d q = reader.numbers<4>(reader.field(item, "rotation", where), where + ".rotation");
    if (std::abs(q.norm() - 1.0) > 1e-6)
      reader.fail(where + ".rotation", "must be a unit quaternion [w, x, y, z]");
    box.rotation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    // Re-normalizing a quaternion that is unit to rounding would change its last bits, and a box read back
    // from disk must equal the one written (or a restart reports it as modified).
    if (std::abs(box.rotation.norm() - 1.0) > 1e-14) box.rotation.normalize();
    box.points = reader.count(reader.field(item, "points", where), where + ".points");
    if (const auto space = item.find("space"); space != item.end())
      box.space = reader.space(*space, where + ".space");
    set.boxes.push_back(box);
  }
  return set;
}

void write_box_file(const std::filesystem::path& path, const BoxSet& set) {
  write_file_atomically(path, to_json(set));
}

BoxSet read_box_file(const std::filesystem::path& path) {
  return box_set_from_json(read_file(path), path.string());
}

std::array<double, 3> box_colour(std::uint64_t id) {
  // Golden-ratio steps around the hue circle keep neighbouring ids apart; the page uses the same formula.
  const double hue = std::fmod(static_cast<double>(id % 1000003) * 0.618033988749895, 1.0) * 6.0;
  const double s = 0.5, v = 0.9;
  const double c = v * s;
  const double x = c * (1 - std::abs(std::fmod(hue, 2.0) - 1));
  const double m = v - c;
  const int sector = static_cast<int>(hue) % 6;
  static constexpr int kOrder[6][3] = {{0, 1, 2}, {1, 0, 2}, {2, 0, 1}, {2, 1, 0}, {1, 2, 0}, {0, 2, 1}};
  const double parts[3] = {c, x, 0.0};
  return {parts[kOrder[sector][0]] + m, parts[kOrder[sector][1]] + m, parts[kOrder[sector][2]] + m};
}

}  // namespace cellmap
