// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one exception type the library throws.

#include <stdexcept>
#include <string>

namespace cellmap {

/// A failure the caller can report as is: the message is one line that says what went wrong and where
/// (file, config key, device), e.g. "config.yaml: region_growing.gap: must be > 0, got -1".
/// Library code never logs or exits on errors; it throws this and leaves the decision to the caller.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace cellmap
