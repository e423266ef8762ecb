// SPDX-License-Identifier: Apache-2.0
// V4L2 source on this machine: no /dev/video* node exists here (and no kernel module can be loaded), so the
// tests check the missing-device and wrong-node paths; negotiation and Z16 decoding are in depth_source_test.
#include "cellmap/sensor/v4l2_source.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "cellmap/common/error.hpp"
#include "sensor/sensor_test_util.hpp"

namespace cellmap {
namespace {

using std::chrono::milliseconds;

using test::fast_retries;

TEST(V4l2SourceTest, MissingDeviceIsACleanDisconnectedStatusNamingIt) {
  V4l2Config config;
  config.device = "/dev/video_cellmap_absent";
  config.reconnect = fast_retries();
  V4l2Source source(config);
  const SourceStatus status = source.open();
  EXPECT_EQ(status.state, SourceState::kDisconnected);
  EXPECT_EQ(status.reason, "v4l2 /dev/video_cellmap_absent: cannot open: No such file or directory");
  // next() retries (20 ms back-off) and never delivers a frame. Until the second attempt, however long a
  // loaded machine takes to get there: only a failing test waits out the minute.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (source.status().attempts < 2 && std::chrono::steady_clock::now() < deadline)
    EXPECT_FALSE(source.next(milliseconds(20)).has_value());
  EXPECT_EQ(source.status().state, SourceState::kDisconnected);
  EXPECT_GE(source.status().attempts, 2u);
}

TEST(V4l2SourceTest, NodeThatIsNotACameraIsAnError) {
  V4l2Config config;
  config.device = "/dev/null";
  V4l2Source source(config);
  const SourceStatus status = source.open();
  EXPECT_EQ(status.state, SourceState::kError);
  EXPECT_EQ(status.reason, "v4l2 /dev/null: not a streaming video capture device");
}

TEST(V4l2SourceTest, ConfigNeedsZ16AndKnownIntrinsics) {
  V4l2Config config;
  config.mode.format = "YUYV";
  EXPECT_THROW(V4l2Source{config}, Error);
  config = V4l2Config{};
  config.mode = DepthMode{424, 240, 30, "Z16"};  // no D435 default for this size
  EXPECT_THROW(V4l2Source{config}, Error);
}

TEST(V4l2ListTest, FolderWithoutVideoDevicesListsNothing) {
  EXPECT_TRUE(list_v4l2_devices("/nonexistent").empty());
  EXPECT_TRUE(list_v4l2_devices(std::filesystem::temp_directory_path().string()).empty());
}

}  // namespace
}  // namespace cellmap
