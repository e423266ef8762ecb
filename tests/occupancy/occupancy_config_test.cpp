// SPDX-License-Identifier: Apache-2.0
#include "cellmap/occupancy/occupancy_config.hpp"

#include <gtest/gtest.h>

#include "support/test_support.hpp"

#include <functional>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

using test::error_of;

OccupancyConfig from_text(const std::string& text) {
  YamlMap root = YamlMap::parse(text, "cell.yaml");
  return OccupancyConfig::from_yaml(root.child("occupancy"));
}

TEST(OccupancyConfigTest, DefaultsAreOctomapsAndValid) {
  const OccupancyConfig c;
  EXPECT_NO_THROW(c.validate());
  EXPECT_DOUBLE_EQ(c.resolution, 0.02);
  EXPECT_DOUBLE_EQ(c.hit, 0.7);
  EXPECT_DOUBLE_EQ(c.miss, 0.4);
  // logodds(0.971) = 3.51, logodds(0.4) = -0.405: 8 misses leave 0.27 (occupied), the 9th -0.13 (free).
  EXPECT_EQ(c.sweeps_to_clear(), 9);
  // logodds(0.1192) = -2.0, logodds(0.7) = 0.847: 3 hits reach 0.54 >= 0.
  EXPECT_EQ(c.sweeps_to_occupy(), 3);
  const OccupancyConfig absent = from_text("other: 1\n");
  EXPECT_DOUBLE_EQ(absent.resolution, 0.02);
  EXPECT_DOUBLE_EQ(absent.max_range, 5.0);
}

TEST(OccupancyConfigTest, ReadsEveryKey) {
  const OccupancyConfig c = from_text(
      "occupancy:\n  resolution: 0.05\n  hit: 0.8\n  miss: 0.3\n  clamp_min: 0.2\n  clamp_max: 0.9\n"
      "  occupied_threshold: 0.6\n  max_range: 3.5\n  threads: 1\n");
  EXPECT_DOUBLE_EQ(c.resolution, 0.05);
  EXPECT_DOUBLE_EQ(c.hit, 0.8);
  EXPECT_DOUBLE_EQ(c.miss, 0.3);
  EXPECT_DOUBLE_EQ(c.clamp_min, 0.2);
  EXPECT_DOUBLE_EQ(c.clamp_max, 0.9);
  EXPECT_DOUBLE_EQ(c.occupied_threshold, 0.6);
  EXPECT_DOUBLE_EQ(c.max_range, 3.5);
  EXPECT_EQ(c.threads, 1);
  // logodds(0.9) = 2.197, logodds(0.6) = 0.405, logodds(0.3) = -0.847: 2.197 - 3 * 0.847 < 0.405 after 3.
  EXPECT_EQ(c.sweeps_to_clear(), 3);
}

TEST(OccupancyConfigTest, ErrorsNameTheKey) {
  EXPECT_EQ(error_of([] { (void)from_text("occupancy:\n  resolutoin: 0.05\n"); }),
            "cell.yaml: occupancy.resolutoin: unknown key");
  EXPECT_EQ(error_of([] { (void)from_text("occupancy:\n  hit: 1.5\n"); }),
            "cell.yaml: occupancy.hit: must be in [0.5, 1], got 1.5");
  EXPECT_EQ(error_of([] { (void)from_text("occupancy:\n  max_range: -1\n"); }),
            "cell.yaml: occupancy.max_range: must be in [0, 100], got -1");
  EXPECT_EQ(error_of([] { (void)from_text("occupancy:\n  resolution: fine\n"); }),
            "cell.yaml: occupancy.resolution: has the wrong type");
  EXPECT_EQ(error_of([] { (void)from_text("occupancy:\n  threads: 0\n"); }),
            "cell.yaml: occupancy.threads: must be an integer in [1, 64], got 0");
  // Relations between fields are checked after reading, still naming the key.
  EXPECT_EQ(error_of([] { (void)from_text("occupancy:\n  hit: 0.5\n"); }),
            "cell.yaml: occupancy.hit: must be in (0.5, 1), got 0.5");
  EXPECT_EQ(error_of([] { (void)from_text("occupancy:\n  clamp_min: 0.6\n"); }),
            "cell.yaml: occupancy.clamp_min: must be in (0, occupied_threshold), got 0.6");
  EXPECT_EQ(error_of([] { (void)from_text("occupancy:\n  max_range: 0\n"); }),
            "cell.yaml: occupancy.max_range: must be in (0, 100] m, got 0");
}

TEST(OccupancyConfigTest, ValidateRejectsNonFinite) {
  OccupancyConfig c;
  c.resolution = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error_of([&] { c.validate(); }).find("occupancy.resolution"), std::string::npos);
}

}  // namespace
}  // namespace cellmap
