// SPDX-License-Identifier: Apache-2.0
#include "cellmap/common/text.hpp"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "cellmap/common/error.hpp"

namespace cellmap {

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> items;
  std::stringstream stream(line);
  std::string item;
  while (std::getline(stream, item, separator)) items.push_back(trim(item));
  if (!line.empty() && line.back() == separator) items.emplace_back();
  return items;
}

std::string lower_extension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

std::string single_line(std::string text) {
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return text;
}

double parse_finite(const std::string& text, const std::string& where) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value)) {
    throw Error(where + ": '" + text + "' is not a finite number");
  }
  return value;
}

}  // namespace cellmap
