// SPDX-License-Identifier: Apache-2.0
// SIGHUP: what a running cellmapd takes from its re-read config file.
#include "reload.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <sstream>

#include "support/test_support.hpp"

namespace cellmap::daemon {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// What the default logger writes while this lives (the previous logger is put back after).
class LogCapture {
 public:
  LogCapture() : previous_(spdlog::default_logger()) {
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(text_);
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("reload_test", sink));
  }
  ~LogCapture() { spdlog::set_default_logger(previous_); }
  [[nodiscard]] std::string text() const { return text_.str(); }

 private:
  std::shared_ptr<spdlog::logger> previous_;
  std::ostringstream text_;
};

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
  const std::optional<double> period = reload_config(file, true, std::nullopt);
  ASSERT_TRUE(period.has_value());
  EXPECT_DOUBLE_EQ(*period, 0.3);
  EXPECT_EQ(spdlog::get_level(), spdlog::level::debug);
}

TEST_F(ReloadTest, CameraKeepsItsSweepGrouping) {
  const auto file = write("log_level: warn\nsweep_period: 0.3\n");
  EXPECT_FALSE(reload_config(file, false, std::nullopt).has_value());
  EXPECT_EQ(spdlog::get_level(), spdlog::level::warn);
}

TEST_F(ReloadTest, BadFileChangesNothing) {
  const auto file = write("log_level: debug\nsweep_period: -1\n");
  EXPECT_FALSE(reload_config(file, true, std::nullopt).has_value());
  EXPECT_EQ(spdlog::get_level(), spdlog::level::info);
  EXPECT_FALSE(reload_config(dir_.path() / "missing.yaml", true, std::nullopt).has_value());
  EXPECT_FALSE(reload_config("", true, std::nullopt).has_value());  // built-in defaults: nothing to re-read
  EXPECT_EQ(spdlog::get_level(), spdlog::level::info);
}

// DDS Security belongs to the participant the daemon joined with: a changed section is reported, naming what
// the file says and what stays in force, and the keys that do reload still apply.
TEST_F(ReloadTest, ChangedSecurityIsReportedAndKeptUntilRestart) {
  const auto file = write("log_level: info\nsweep_period: 0.3\nsecurity: {directory: keys, role: daemon}\n");
  const security::Setting running{dir_.path() / "keys", security::Role::kDaemon};
  {
    LogCapture log;
    EXPECT_EQ(reload_config(file, true, std::nullopt), 0.3);
    EXPECT_THAT(log.text(), HasSubstr("SIGHUP: `security` now says " + running.directory.string() +
                                      " as daemon, but DDS Security stays off until restart"));
  }
  {
    LogCapture log;
    const security::Setting other_role{running.directory, security::Role::kTool};
    EXPECT_EQ(reload_config(file, true, other_role), 0.3);
    EXPECT_THAT(log.text(), HasSubstr("stays " + running.directory.string() + " as tool until restart"));
  }
  {
    LogCapture log;  // the same directory spelled another way, the same role: nothing to say
    const security::Setting same{dir_.path() / "." / "keys", security::Role::kDaemon};
    EXPECT_EQ(reload_config(file, true, same), 0.3);
    EXPECT_THAT(log.text(), Not(HasSubstr("security")));
  }
  {
    LogCapture log;  // security on at start, the section removed since
    EXPECT_EQ(reload_config(write("sweep_period: 0.4\n"), true, running), 0.4);
    EXPECT_THAT(log.text(), HasSubstr("`security` now says off, but DDS Security stays " +
                                      running.directory.string() + " as daemon until restart"));
  }
}

}  // namespace
}  // namespace cellmap::daemon
