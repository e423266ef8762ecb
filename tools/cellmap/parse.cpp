// SPDX-License-Identifier: Apache-2.0
#include "parse.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"

namespace cellmap::cli {

std::vector<double> parse_numbers(const std::string& text, const std::string& what,
                                  const std::vector<std::size_t>& allowed_counts) {
  std::vector<double> values;
  for (const std::string& item : split(text, ',')) values.push_back(parse_finite(item, what));
  if (std::find(allowed_counts.begin(), allowed_counts.end(), values.size()) == allowed_counts.end()) {
    std::string counts;
    for (std::size_t n : allowed_counts) counts += (counts.empty() ? "" : " or ") + std::to_string(n);
    throw Error(what + ": expected " + counts + " comma-separated numbers, got " +
                std::to_string(values.size()));
  }
  return values;
}

}  // namespace cellmap::cli
