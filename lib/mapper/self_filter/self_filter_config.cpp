// SPDX-License-Identifier: Apache-2.0
#include <sstream>
#include <string>

#include "cellmap/common/error.hpp"
#include "cellmap/self_filter/self_filter.hpp"

namespace cellmap {
namespace {

[[noreturn]] void bad(const std::string& field, const std::string& rule, double value) {
  std::ostringstream msg;
  msg << "self_filter." << field << ": " << rule << ", got " << value;
  throw Error(msg.str());
}

}  // namespace

void SelfFilterConfig::validate() const {
  if (!(padding_scale >= 1.0 && padding_scale <= 10.0))
    bad("padding_scale", "must be in [1, 10]", padding_scale);
  if (!(padding >= 0.0 && padding <= 1.0)) bad("padding", "must be in [0, 1] m", padding);
}

SelfFilterConfig SelfFilterConfig::from_yaml(YamlMap section) {
  SelfFilterConfig c;
  c.enabled = section.get<bool>("enabled", c.enabled);
  c.padding_scale = section.number("padding_scale", c.padding_scale, 1.0, 10.0);
  c.padding = section.number("padding", c.padding, 0.0, 1.0);
  section.expect_all_read();
  c.validate();
  return c;
}

}  // namespace cellmap
