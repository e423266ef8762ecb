#include "cellmap/common/yaml_map.hpp"

#include <cmath>
#include <sstream>

#include "cellmap/common/atomic_file.hpp"

namespace cellmap {

YamlMap::YamlMap(YAML::Node node, std::string path, std::string source)
    : node_(std::move(node)), path_(std::move(path)), source_(std::move(source)) {
  if (!node_ || node_.IsNull()) {
    node_ = YAML::Node(YAML::NodeType::Map);
  } else if (!node_.IsMap()) {
    const std::string where = source_.empty() ? "" : source_ + ": ";
    throw Error(where + (path_.empty() ? std::string("document") : path_) + ": must be a mapping of keys");
  }
}

YamlMap YamlMap::parse(const std::string& text, const std::string& source) {
  try {
    return YamlMap(YAML::Load(text), "", source);
  } catch (const YAML::ParserException& e) {
    std::ostringstream msg;
    msg << source << ": YAML syntax error at line " << e.mark.line + 1 << ", column " << e.mark.column + 1
        << ": " << e.msg;
    throw Error(msg.str());
  }
}

YamlMap YamlMap::load(const std::string& file) {
  return parse(read_file(file), file);
}

bool YamlMap::has(const std::string& key) const {
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

YamlMap YamlMap::child(const std::string& key) {
  read_.insert(key);
  return YamlMap(node_[key], key_path(key), source_);
}

YAML::Node YamlMap::node(const std::string& key) {
  read_.insert(key);
  return node_[key];
}

void YamlMap::expect_all_read() const {
  for (const auto& entry : node_) {
    const std::string key = entry.first.as<std::string>();
    if (read_.count(key) == 0) fail(key, "unknown key");
  }
}

void YamlMap::fail(const std::string& key, const std::string& reason) const {
  const std::string where = source_.empty() ? "" : source_ + ": ";
  throw Error(where + key_path(key) + ": " + reason);
}

std::string YamlMap::key_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

}  // namespace cellmap
