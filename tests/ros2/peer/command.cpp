// SPDX-License-Identifier: Apache-2.0
#include "command.hpp"

#include <cerrno>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <type_traits>

namespace ros2_peer {

namespace {

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  if (text.empty()) return parts;
  std::string::size_type start = 0;
  for (;;) {
    const auto end = text.find(separator, start);
    parts.push_back(text.substr(start, end - start));
    if (end == std::string::npos) return parts;
    start = end + 1;
  }
}

}  // namespace

template <typename T>
T parse_number(const std::string& text, const std::string& what) {
  const auto fail = [&] { return CommandError(what + ": '" + text + "' is not a number of its type"); };
  if (text.empty() || text.front() == ' ') throw fail();
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  T value{};
  if constexpr (std::is_same_v<T, float>) {
    value = std::strtof(begin, &end);
  } else if constexpr (std::is_same_v<T, double>) {
    value = std::strtod(begin, &end);
  } else if constexpr (std::is_signed_v<T>) {
    const long long parsed = std::strtoll(begin, &end, 10);
    if (parsed < std::numeric_limits<T>::min() || parsed > std::numeric_limits<T>::max()) throw fail();
    value = static_cast<T>(parsed);
  } else {
    // strtoull takes "-1" as ULLONG_MAX; a count or size is never negative.
    if (text.front() == '-') throw fail();
    const unsigned long long parsed = std::strtoull(begin, &end, 10);
    if (parsed > std::numeric_limits<T>::max()) throw fail();
    value = static_cast<T>(parsed);
  }
  // Overflow is an error; strtod's ERANGE on a denormal result is not worth refusing a test's value for.
  if (end != begin + text.size() || (errno == ERANGE && !std::is_floating_point_v<T>)) throw fail();
  return value;
}

template std::int64_t parse_number<std::int64_t>(const std::string&, const std::string&);
template std::uint64_t parse_number<std::uint64_t>(const std::string&, const std::string&);
template std::uint32_t parse_number<std::uint32_t>(const std::string&, const std::string&);
template std::uint8_t parse_number<std::uint8_t>(const std::string&, const std::string&);
template double parse_number<double>(const std::string&, const std::string&);
template float parse_number<float>(const std::string&, const std::string&);

Command Command::parse(const std::string& line) {
  Command command;
  std::istringstream words(line);
  std::string word;
  while (words >> word) {
    if (command.verb_.empty()) {
      command.verb_ = word;
      continue;
    }
    const auto equals = word.find('=');
    if (equals == std::string::npos || equals == 0) throw CommandError("'" + word + "' is not key=value");
    const std::string key = word.substr(0, equals);
    if (!command.words_.emplace(key, word.substr(equals + 1)).second)
      throw CommandError(key + " given twice");
  }
  if (command.verb_.empty()) throw CommandError("empty command");
  return command;
}

void Command::allow_only(const std::vector<std::string>& allowed) const {
  for (const auto& [key, value] : words_) {
    bool known = false;
    for (const std::string& name : allowed) known = known || name == key;
    if (!known) throw CommandError(verb_ + " takes no " + key);
  }
}

const std::string& Command::text(const std::string& key) const {
  const auto found = words_.find(key);
  if (found == words_.end()) throw CommandError(verb_ + " needs " + key + "=");
  return found->second;
}

std::string Command::text_or(const std::string& key, const std::string& fallback) const {
  return has(key) ? text(key) : fallback;
}

std::int64_t Command::int64(const std::string& key) const {
  return parse_number<std::int64_t>(text(key), key);
}
std::uint32_t Command::uint32(const std::string& key) const {
  return parse_number<std::uint32_t>(text(key), key);
}
double Command::float64(const std::string& key) const {
  return parse_number<double>(text(key), key);
}
float Command::float32(const std::string& key) const {
  return parse_number<float>(text(key), key);
}

bool Command::flag(const std::string& key) const {
  const std::string& value = text(key);
  if (value != "0" && value != "1") throw CommandError(key + " must be 0 or 1, not '" + value + "'");
  return value == "1";
}

std::vector<std::string> Command::list(const std::string& key) const {
  return split(text(key), ',');
}

std::vector<double> Command::float64_list(const std::string& key) const {
  std::vector<double> values;
  for (const std::string& item : list(key)) values.push_back(parse_number<double>(item, key));
  return values;
}

std::vector<FieldSpec> Command::fields(const std::string& key) const {
  std::vector<FieldSpec> fields;
  for (const std::string& item : list(key)) {
    const std::vector<std::string> parts = split(item, ':');
    if (parts.size() != 4) throw CommandError(key + ": '" + item + "' is not NAME:OFFSET:DATATYPE:COUNT");
    fields.push_back({parts[0], parse_number<std::uint32_t>(parts[1], key + " offset"),
                      parse_number<std::uint8_t>(parts[2], key + " datatype"),
                      parse_number<std::uint32_t>(parts[3], key + " count")});
  }
  return fields;
}

}  // namespace ros2_peer
