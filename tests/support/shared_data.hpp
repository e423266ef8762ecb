#pragma once
// Tests that read ../shared/data (CELLMAP_SHARED_DATA) skip when it is absent, so a checkout without the
// data still builds and tests; with CELLMAP_REQUIRE_DATA=1 (CI, scripts/test) they fail instead, so a green
// run means they ran.

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace cellmap::test {

/// True when CELLMAP_REQUIRE_DATA=1: missing shared data is a failure, not a skip.
inline bool shared_data_required() {
  const char* value = std::getenv("CELLMAP_REQUIRE_DATA");
  return value != nullptr && std::strcmp(value, "1") == 0;
}

}  // namespace cellmap::test

/// Ends the test when `required_path` does not exist: skipped, or failed under CELLMAP_REQUIRE_DATA=1.
#define CELLMAP_SKIP_WITHOUT_DATA(required_path)                                                        \
  if (const std::filesystem::path cellmap_data_path_{required_path};                                    \
      !std::filesystem::exists(cellmap_data_path_)) {                                                   \
    if (::cellmap::test::shared_data_required()) {                                                      \
      FAIL() << cellmap_data_path_ << " is absent and CELLMAP_REQUIRE_DATA=1 requires the shared data"; \
    }                                                                                                   \
    GTEST_SKIP() << cellmap_data_path_ << " is absent (shared test data): skipping";                    \
  }                                                                                                     \
  static_assert(true)
