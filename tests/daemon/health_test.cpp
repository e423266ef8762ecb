// SPDX-License-Identifier: Apache-2.0
// cellmapd's health: which state the status topic shows, and why.
#include "health.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap::daemon {
namespace {

TEST(HealthTest, StartingUntilTheFirstSweepThenRunning) {
  Health health("press-3", {"wrist"});
  EXPECT_EQ(health.state(), std::make_pair(DaemonState::kStarting, std::string()));
  transport::CellStatus status = health.status();
  EXPECT_EQ(status.cell, "press-3");
  EXPECT_EQ(status.state, "starting");
  ASSERT_EQ(status.sensors.size(), 1u);
  EXPECT_EQ(status.sensors[0].name, "wrist");
  EXPECT_EQ(status.sensors[0].state, "starting");
  EXPECT_EQ(status.sweeps, 0u);

  health.set_sensor("wrist", SourceState::kConnected);
  health.sweep_processed(1, 1234);
  status = health.status();
  EXPECT_EQ(status.state, "running");
  EXPECT_EQ(status.reason, "");
  EXPECT_EQ(status.sensors[0].state, "streaming");
  EXPECT_EQ(status.sweeps, 1u);
  EXPECT_EQ(status.last_sweep_ns, 1234);
}

TEST(HealthTest, DegradedWithTheReasonThatMattersMost) {
  Health health("press-3", {"wrist"});
  health.set_sensor("wrist", SourceState::kConnected);
  health.sweep_processed(1, 1);

  health.sweep_failed("sweep 2: too many points");
  EXPECT_EQ(health.state(), std::make_pair(DaemonState::kDegraded, std::string("sweep 2: too many points")));
  health.sweep_processed(3, 3);  // a sweep that went through ends it
  EXPECT_EQ(health.state().first, DaemonState::kRunning);

  health.set_sensor("wrist", SourceState::kDisconnected, "openni2: no devices found");
  EXPECT_EQ(health.state(),
            std::make_pair(DaemonState::kDegraded,
                           std::string("sensor 'wrist': disconnected: openni2: no devices found")));
  EXPECT_EQ(health.status().sensors[0].state, "disconnected: openni2: no devices found");

  // A version that is not out weighs most: subscribers do not have what the daemon holds.
  health.set_version_fault("version 7 not saved: state/x: write failed: No space left on device");
  EXPECT_EQ(health.status().state, "degraded");
  EXPECT_EQ(health.status().reason, "version 7 not saved: state/x: write failed: No space left on device");
  health.set_version_fault("");
  health.set_sensor("wrist", SourceState::kConnected);
  EXPECT_EQ(health.status().state, "running");

  health.stop();
  EXPECT_EQ(health.status().state, "stopped");
}

TEST(HealthTest, OneSensorDownDegradesTheCellAndEverySensorIsReported) {
  Health health("arm-cell", {"post", "wrist"});
  health.set_sensor("post", SourceState::kConnected);
  health.set_sensor("wrist", SourceState::kConnected);
  health.sweep_processed(1, 1);
  EXPECT_EQ(health.state().first, DaemonState::kRunning);

  health.set_sensor("wrist", SourceState::kDisconnected, "v4l2: /dev/video2: No such device");
  EXPECT_EQ(health.state(),
            std::make_pair(DaemonState::kDegraded,
                           std::string("sensor 'wrist': disconnected: v4l2: /dev/video2: No such device")));
  const transport::CellStatus status = health.status();
  ASSERT_EQ(status.sensors.size(), 2u);
  EXPECT_EQ(status.sensors[0].name, "post");
  EXPECT_EQ(status.sensors[0].state, "streaming");
  EXPECT_EQ(status.sensors[1].name, "wrist");
  EXPECT_EQ(status.sensors[1].state, "disconnected: v4l2: /dev/video2: No such device");
  EXPECT_THROW(health.set_sensor("kinect", SourceState::kConnected), Error);
}

TEST(HealthTest, NamesMatchTheStatusContract) {
  EXPECT_STREQ(to_string(DaemonState::kStarting), "starting");
  EXPECT_STREQ(to_string(DaemonState::kRunning), "running");
  EXPECT_STREQ(to_string(DaemonState::kDegraded), "degraded");
  EXPECT_STREQ(to_string(DaemonState::kStopped), "stopped");
  EXPECT_EQ(sensor_text(SourceState::kEnded, ""), "ended");
  EXPECT_EQ(sensor_text(SourceState::kError, "bad mode"), "error: bad mode");
}

}  // namespace
}  // namespace cellmap::daemon
