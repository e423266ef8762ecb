// SPDX-License-Identifier: Apache-2.0
#pragma once
// One line of ros2_peer's input: a verb and `key=value` words, e.g.
//   pub-joints topic=/joint_states names=a,b positions=1.5,-2
// Values hold no spaces. Every getter throws CommandError with a reason the peer prints and goes on.

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ros2_peer {

class CommandError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A sensor_msgs/PointField as given on the command line: NAME:OFFSET:DATATYPE:COUNT.
struct FieldSpec {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;
  std::uint32_t count = 0;
};

class Command final {
 public:
  /// Splits `line` at blanks: the first word is the verb, every other one `key=value` (the value may be
  /// empty). @throws CommandError on an empty line, a word without '=' or a key given twice.
  static Command parse(const std::string& line);

  [[nodiscard]] const std::string& verb() const { return verb_; }
  [[nodiscard]] bool has(const std::string& key) const { return words_.count(key) != 0; }
  /// @throws CommandError naming the first key not in `allowed`, so a typo is not silently ignored.
  void allow_only(const std::vector<std::string>& allowed) const;

  /// The value of `key`. @throws CommandError if it is missing.
  [[nodiscard]] const std::string& text(const std::string& key) const;
  [[nodiscard]] std::string text_or(const std::string& key, const std::string& fallback) const;
  /// Decimal integers in the range of the type. @throws CommandError if missing, malformed or out of range.
  [[nodiscard]] std::int64_t int64(const std::string& key) const;
  [[nodiscard]] std::uint32_t uint32(const std::string& key) const;
  /// 0 or 1.
  [[nodiscard]] bool flag(const std::string& key) const;
  /// strtod/strtof syntax, so "nan", "inf" and "-inf" are accepted.
  [[nodiscard]] double float64(const std::string& key) const;
  [[nodiscard]] float float32(const std::string& key) const;
  /// A comma-separated list; an empty value is an empty list.
  [[nodiscard]] std::vector<std::string> list(const std::string& key) const;
  [[nodiscard]] std::vector<double> float64_list(const std::string& key) const;
  /// fields=NAME:OFFSET:DATATYPE:COUNT[,...]; DATATYPE is the number (7 = FLOAT32), not checked.
  [[nodiscard]] std::vector<FieldSpec> fields(const std::string& key) const;

 private:
  std::string verb_;
  std::map<std::string, std::string> words_;
};

/// Parses one number of `what` (strict: the whole text, in range of T). @throws CommandError otherwise.
template <typename T>
T parse_number(const std::string& text, const std::string& what);

}  // namespace ros2_peer
