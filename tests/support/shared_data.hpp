// SPDX-License-Identifier: Apache-2.0
#pragma once
// Tests that read the shared data (real sensor frames, robot packages, ROS 2 message files: ../shared/data
// beside the checkout, or wherever CELLMAP_SHARED_DATA points) skip when it is absent, so a checkout without
// it still builds and tests; with CELLMAP_REQUIRE_DATA=1 (what scripts/test sets under CI) they fail instead,
// so a green CI run means they ran. scripts/test counts the skips by the phrase kSharedDataMissing.

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace cellmap::test {

/// What every skip for missing shared data says, word for word: scripts/test counts those skips by it.
inline constexpr const char* kSharedDataMissing = "shared test data missing (CELLMAP_SHARED_DATA)";

/// The shared data folder: the environment's CELLMAP_SHARED_DATA if set and not empty, else the one the
/// build was configured with (CMake's CELLMAP_SHARED_DATA, ../shared/data by default). Read at run time, so
/// `CELLMAP_SHARED_DATA=/elsewhere ctest` points every test at another copy, or at none.
inline std::filesystem::path shared_data_dir() {
  const char* value = std::getenv("CELLMAP_SHARED_DATA");
  return value != nullptr && *value != '\0' ? std::filesystem::path(value)
                                            : std::filesystem::path(CELLMAP_SHARED_DATA);
}

/// True when CELLMAP_REQUIRE_DATA=1: missing shared data is a failure, not a skip.
inline bool shared_data_required() {
  const char* value = std::getenv("CELLMAP_REQUIRE_DATA");
  return value != nullptr && std::strcmp(value, "1") == 0;
}

}  // namespace cellmap::test

/// Ends the test when `required_path` does not exist: skipped, or failed under CELLMAP_REQUIRE_DATA=1. Put it
/// first in a test, before any check, so a skipped test has checked nothing and says so.
#define CELLMAP_SKIP_WITHOUT_DATA(required_path)                                                        \
  if (const std::filesystem::path cellmap_data_path_{required_path};                                    \
      !std::filesystem::exists(cellmap_data_path_)) {                                                   \
    if (::cellmap::test::shared_data_required()) {                                                      \
      FAIL() << cellmap_data_path_ << " is absent and CELLMAP_REQUIRE_DATA=1 requires the shared data"; \
    }                                                                                                   \
    GTEST_SKIP() << ::cellmap::test::kSharedDataMissing << ": " << cellmap_data_path_ << " is absent";  \
  }                                                                                                     \
  static_assert(true)
