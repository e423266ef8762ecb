// SIGHUP: what a running cellmapd takes from its re-read config file.
#include "reload.hpp"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <fstream>

#include "support/test_support.hpp"

namespace cellmap::daemon {
namespace {

class ReloadTest : public ::testing::Test {
 protected:
  void SetUp() override { spdlog::set_level(spdlog::level::info); }
  void TearDown() override { spdlog::set_level(spdlog::level::info); }

  std::filesystem::path write(const std::string& yaml) const {
    const std::filesystem::path file = dir_.path() / "cellmapd.yaml";
    std::ofstream(file, std::ios::trunc) << yaml;
    return file;
  }

  test::TempDir dir_;
};

TEST_F(ReloadTest, SimTakesTheLogLevelAndTheSweepPeriod) {
  const auto file = write("log_level: debug\nsweep_period: 0.3\noccupancy: {resolution: 0.05}\n");
  const std::optional<double> period = reload_config(file, true);
  ASSERT_TRUE(period.has_value());
  EXPECT_DOUBLE_EQ(*period, 0.3);
  EXPECT_EQ(spdlog::get_level(), spdlog::level::debug);
}

TEST_F(ReloadTest, CameraKeepsItsSweepGrouping) {
  const auto file = write("log_level: warn\nsweep_period: 0.3\n");
  EXPECT_FALSE(reload_config(file, false).has_value());
  EXPECT_EQ(spdlog::get_level(), spdlog::level::warn);
}

TEST_F(ReloadTest, BadFileChangesNothing) {
  const auto file = write("log_level: debug\nsweep_period: -1\n");
  EXPECT_FALSE(reload_config(file, true).has_value());
  EXPECT_EQ(spdlog::get_level(), spdlog::level::info);
  EXPECT_FALSE(reload_config(dir_.path() / "missing.yaml", true).has_value());
  EXPECT_FALSE(reload_config("", true).has_value());  // built-in defaults: nothing to re-read
  EXPECT_EQ(spdlog::get_level(), spdlog::level::info);
}

}  // namespace
}  // namespace cellmap::daemon
