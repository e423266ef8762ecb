// SPDX-License-Identifier: Apache-2.0
#include "cellmap/config/yaml_map.hpp"

#include <cmath>
#include <sstream>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/text.hpp"

namespace cellmap {
namespace {
thread_local YamlKeyLog* active_key_log = nullptr;
}  // namespace

YamlKeyLog::YamlKeyLog() : outer_(active_key_log) {
  active_key_log = this;
}

YamlKeyLog::~YamlKeyLog() {
  active_key_log = outer_;
}

void YamlMap::mark_read(const std::string& key) {
  read_.insert(key);
  if (active_key_log) active_key_log->keys_.insert(key_path(key));
}

YamlMap::YamlMap(YAML::Node node, std::string path, std::string source)
    : node_(std::move(node)), path_(std::move(path)), source_(std::move(source)) {
  const std::string where = (source_.empty() ? "" : source_ + ": ") + (path_.empty() ? "document" : path_);
  if (!node_ || node_.IsNull()) {
    node_ = YAML::Node(YAML::NodeType::Map);
  } else if (!node_.IsMap()) {
    throw Error(where + ": must be a mapping of keys");
  }
  for (const auto& entry : node_) {
    if (!entry.first.IsScalar()) {
      throw Error(where + ": the key at line " + std::to_string(entry.first.Mark().line + 1) +
                  " is not a plain name");
    }
  }
}

YamlMap YamlMap::parse(const std::string& text, const std::string& source) {
  try {
    return YamlMap(YAML::Load(text), "", source);
  } catch (const YAML::ParserException& e) {
    std::ostringstream msg;
    msg << source << ": YAML syntax error at line " << e.mark.line + 1 << ", column " << e.mark.column + 1
        << ": " << single_line(e.msg);
    throw Error(msg.str());
  }
}

YamlMap YamlMap::load(const std::string& file) {
  return parse(read_file(file), file);
}

bool YamlMap::has(const std::string& key) const {
  if (active_key_log) active_key_log->keys_.insert(key_path(key));
  return static_cast<bool>(node_[key]);
}

double YamlMap::number(const std::string& key, double fallback, double min, double max) {
  const double value = get<double>(key, fallback);
  if (!std::isfinite(value) || value < min || value > max) {
    std::ostringstream reason;
    reason << "must be in [" << min << ", " << max << "], got " << value;
    fail(key, reason.str());
  }
  return value;
}

long YamlMap::integer(const std::string& key, long fallback, long min, long max) {
  const long value = get<long>(key, fallback);
  if (value < min || value > max) {
    std::ostringstream reason;
    reason << "must be an integer in [" << min << ", " << max << "], got " << value;
    fail(key, reason.str());
  }
  return value;
}

std::vector<double> YamlMap::numbers(const std::string& key, std::size_t count) {
  const std::vector<double> values = require<std::vector<double>>(key);
  if (count != 0 && values.size() != count) {
    fail(key, "must have " + std::to_string(count) + " numbers, got " + std::to_string(values.size()));
  }
  for (double v : values) {
    if (!std::isfinite(v)) fail(key, "must be finite numbers");
  }
  return values;
}

Eigen::Vector3d YamlMap::vector3(const std::string& key) {
  const std::vector<double> v = numbers(key, 3);
  return {v[0], v[1], v[2]};
}

Eigen::Quaterniond YamlMap::unit_quaternion(const std::string& key) {
  const std::vector<double> v = numbers(key, 4);
  const Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    fail(key, "must be a unit quaternion [w, x, y, z] (norm " + std::to_string(q.norm()) + ")");
  }
  return q.normalized();
}

Eigen::Isometry3d YamlMap::pose(const std::string& key) {
  YamlMap map = child(key);
  if (map.has("position") && map.has("translation")) {
    map.fail("translation", "is another spelling of position: give one of them");
  }
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  for (const char* position : {"position", "translation"}) {
    if (map.has(position)) X.translation() = map.vector3(position);
  }
  if (map.has("rotation")) X.linear() = map.unit_quaternion("rotation").toRotationMatrix();
  map.expect_all_read();
  return X;
}

YamlMap YamlMap::child(const std::string& key) {
  mark_read(key);
  return YamlMap(node_[key], key_path(key), source_);
}

YAML::Node YamlMap::node(const std::string& key) {
  mark_read(key);
  return node_[key];
}

void YamlMap::expect_all_read() const {
  const std::vector<std::string> unread = unread_keys();
  if (!unread.empty()) fail(unread.front(), "unknown key");
}

std::vector<std::string> YamlMap::unread_keys() const {
  std::vector<std::string> unread;
  for (const auto& entry : node_) {
    std::string key = entry.first.as<std::string>();
    if (read_.count(key) == 0) unread.push_back(std::move(key));
  }
  return unread;
}

void YamlMap::fail(const std::string& key, const std::string& reason) const {
  const std::string where = source_.empty() ? "" : source_ + ": ";
  // Keys and the values a reason quotes come from the file: keep the message on one line whatever they hold.
  throw Error(where + single_line(key_path(key)) + ": " + single_line(reason));
}

std::string YamlMap::key_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

}  // namespace cellmap
