// SPDX-License-Identifier: Apache-2.0
#pragma once
// Strict reading of YAML configuration maps: every key is either read or reported as unknown.

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cellmap/common/error.hpp"

namespace cellmap {

/// A view of one YAML mapping that remembers which keys were read, so that `expect_all_read()` can reject
/// misspelt or unsupported keys. Errors name the full key path ("segment.region_growing.gap") and, when the
/// map came from a file, the file. Copyable; not thread-safe.
class YamlMap {
 public:
  /// @param node  a YAML mapping, or a null node (treated as an empty map: every key takes its default).
  /// @param path  dotted key path of this map inside its document ("" for the root), used in messages.
  /// @param source  file name or other origin, used as the message prefix ("" for none).
  /// @throws Error if `node` is neither null nor a mapping, or has a key that is not a scalar.
  YamlMap(YAML::Node node, std::string path, std::string source = "");

  /// Parses a whole YAML document. @throws Error with the parser's line and column on a syntax error.
  [[nodiscard]] static YamlMap parse(const std::string& text, const std::string& source);
  /// Reads and parses a YAML file. @throws Error if it cannot be read or parsed.
  [[nodiscard]] static YamlMap load(const std::string& file);

  [[nodiscard]] bool has(const std::string& key) const;

  /// The value of `key` converted to T, or `fallback` when absent.
  /// @throws Error naming the key if the value does not convert to T.
  template <typename T>
  [[nodiscard]] T get(const std::string& key, const T& fallback) {
    if (!has(key)) {
      mark_read(key);
      return fallback;
    }
    return require<T>(key);
  }

  /// The value of `key` converted to T. @throws Error naming the key if absent or not convertible.
  template <typename T>
  [[nodiscard]] T require(const std::string& key) {
    mark_read(key);
    const YAML::Node value = node_[key];
    if (!value) fail(key, "is required");
    try {
      return value.as<T>();
    } catch (const YAML::Exception&) {
      fail(key, "has the wrong type");
    }
  }

  /// A number in [min, max]. @throws Error naming the key and the allowed range otherwise.
  [[nodiscard]] double number(const std::string& key, double fallback, double min, double max);
  /// An integer in [min, max]. @throws Error naming the key and the allowed range otherwise.
  [[nodiscard]] long integer(const std::string& key, long fallback, long min, long max);

  /// A list of finite numbers; with `count` > 0 exactly that many. @throws Error naming the key otherwise.
  [[nodiscard]] std::vector<double> numbers(const std::string& key, std::size_t count = 0);
  /// [x, y, z], finite. @throws Error naming the key otherwise.
  [[nodiscard]] Eigen::Vector3d vector3(const std::string& key);
  /// A unit quaternion [w, x, y, z] (norm within 1e-3 of 1), returned normalized. @throws Error naming the
  /// key.
  [[nodiscard]] Eigen::Quaterniond unit_quaternion(const std::string& key);
  /// The pose under `key`, identity when absent: `{position: [x, y, z], rotation: [w, x, y, z]}`, both
  /// optional (identity parts); `translation` is read as another spelling of `position`. Every pose in the
  /// configuration files (the sensor mount X_ES, a robot's base, the gantry's tool pose) uses this schema.
  /// @throws Error naming the key for unknown keys, both spellings at once, or bad values.
  [[nodiscard]] Eigen::Isometry3d pose(const std::string& key);

  /// The nested map under `key` (an empty map when absent). @throws Error if present but not a map.
  [[nodiscard]] YamlMap child(const std::string& key);
  /// The raw node under `key` (for sequences), marked as read; null when absent.
  [[nodiscard]] YAML::Node node(const std::string& key);
  /// The underlying node of this map.
  [[nodiscard]] const YAML::Node& node() const { return node_; }

  /// @throws Error naming the first key of this map that was never read ("unknown key").
  void expect_all_read() const;
  /// The keys of this map that were never read, in the file's order (what expect_all_read() refuses), for a
  /// reader that reports every unknown key rather than the first.
  [[nodiscard]] std::vector<std::string> unread_keys() const;

  /// @throws Error "<source>: <path>.<key>: <reason>".
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const;

  [[nodiscard]] std::string key_path(const std::string& key) const;
  [[nodiscard]] const std::string& source() const { return source_; }

 private:
  void mark_read(const std::string& key);

  YAML::Node node_;
  std::string path_;
  std::string source_;
  std::set<std::string> read_;
};

/// Records, while it lives, the full path of every key that any YamlMap of this thread reads or asks about
/// (`has`), e.g. "source.openni2.intrinsics": the keys a reader accepts, taken from the reader itself, for
/// the check that the documentation lists each of them. Nests: the innermost log records.
class YamlKeyLog final {
 public:
  YamlKeyLog();
  ~YamlKeyLog();
  YamlKeyLog(const YamlKeyLog&) = delete;
  YamlKeyLog& operator=(const YamlKeyLog&) = delete;

  [[nodiscard]] const std::set<std::string>& keys() const { return keys_; }

 private:
  friend class YamlMap;
  std::set<std::string> keys_;
  YamlKeyLog* outer_;
};

}  // namespace cellmap
