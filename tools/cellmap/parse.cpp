#include "parse.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cellmap/common/error.hpp"

namespace cellmap::cli {

std::vector<double> parse_numbers(const std::string& text, const std::string& what,
                                  const std::vector<std::size_t>& allowed_counts) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    std::size_t used = 0;
    double value = 0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(value)) {
      throw Error(what + ": '" + item + "' is not a finite number");
    }
    values.push_back(value);
  }
  if (std::find(allowed_counts.begin(), allowed_counts.end(), values.size()) == allowed_counts.end()) {
    std::string counts;
    for (std::size_t n : allowed_counts) counts += (counts.empty() ? "" : " or ") + std::to_string(n);
    throw Error(what + ": expected " + counts + " comma-separated numbers, got " +
                std::to_string(values.size()));
  }
  return values;
}

}  // namespace cellmap::cli
