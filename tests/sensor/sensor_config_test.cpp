// SPDX-License-Identifier: Apache-2.0
// Per-sensor configuration: the source chosen by `source:` and its settings.
#include "cellmap/sensor/sensor_config.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

SensorConfig parse(const std::string& yaml) {
  YamlMap map = YamlMap::parse(yaml, "cell.yaml");
  return read_sensor_config(map, "wrist");
}

TEST(SensorConfigTest, OpenNI2WithExtrinsicAndIntrinsics) {
  const SensorConfig config = parse(R"(
source: openni2
X_ES: {translation: [0.0, 0.05, 0.1], rotation: [0.7071067811865476, 0, 0, 0.7071067811865476]}
pose_tolerance: 0.02
openni2:
  uri: /data/sweep.oni
  width: 320
  height: 240
  format: DEPTH_100_UM
  intrinsics: {fx: 285, fy: 285, cx: 160, cy: 120}
  frame_timeout: 1.5
  reconnect: {initial_backoff: 0.25, max_backoff: 8}
)");
  EXPECT_EQ(config.name, "wrist");
  EXPECT_DOUBLE_EQ(config.pose_tolerance, 0.02);
  EXPECT_TRUE(config.X_ES.translation().isApprox(Eigen::Vector3d(0, 0.05, 0.1)));
  EXPECT_TRUE((config.X_ES.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  const auto& openni2 = std::get<OpenNI2Config>(config.source);
  EXPECT_EQ(openni2.uri, "/data/sweep.oni");
  EXPECT_EQ(openni2.mode.to_string(), "320x240@30 DEPTH_100_UM");
  ASSERT_TRUE(openni2.intrinsics.has_value());
  EXPECT_EQ(openni2.intrinsics->width, 320);
  EXPECT_DOUBLE_EQ(openni2.reconnect.frame_timeout, 1.5);
  EXPECT_DOUBLE_EQ(openni2.reconnect.initial_backoff, 0.25);
  const auto source = make_depth_source(config);
  EXPECT_EQ(source->name(), "wrist");
  EXPECT_EQ(source->status().state, SourceState::kClosed);
}

TEST(SensorConfigTest, V4l2DefaultsToTheRealSenseIntrinsics) {
  const SensorConfig config = parse("source: v4l2\nv4l2: {device: /dev/video4, width: 640, height: 480}\n");
  const auto& v4l2 = std::get<V4l2Config>(config.source);
  EXPECT_EQ(v4l2.device, "/dev/video4");
  ASSERT_TRUE(v4l2.intrinsics.has_value());
  EXPECT_DOUBLE_EQ(v4l2.intrinsics->fx, realsense_d435_intrinsics(640, 480).fx);
  EXPECT_DOUBLE_EQ(v4l2.intrinsics->min_range, 0.3);
  EXPECT_EQ(v4l2.intrinsics->smoothing_radius, kStereoSmoothingRadius);
  EXPECT_EQ(std::get<V4l2Config>(parse("source: v4l2\nv4l2: {smoothing_radius: 0}\n").source)
                .intrinsics->smoothing_radius,
            0);
  EXPECT_NE(dynamic_cast<V4l2Source*>(make_depth_source(config).get()), nullptr);
}

TEST(SensorConfigTest, Replay) {
  const SensorConfig config =
      parse("source: replay\nreplay: {directory: /data/field, playback: fixed, rate_hz: 5}\n");
  const auto& replay = std::get<ReplayConfig>(config.source);
  EXPECT_EQ(replay.directory, "/data/field");
  EXPECT_EQ(replay.playback, ReplayConfig::Playback::kFixed);
  EXPECT_DOUBLE_EQ(replay.rate_hz, 5.0);
}

TEST(SensorConfigTest, ErrorsNameTheKey) {
  const auto message = [](const std::string& yaml) {
    try {
      (void)parse(yaml);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("source: kinect\n").find("source: must be openni2, v4l2 or replay"), std::string::npos);
  EXPECT_NE(message("source: openni2\nopenni2: {format: RGB888}\n").find("openni2.format"),
            std::string::npos);
  EXPECT_NE(message("source: v4l2\nv4l2: {width: 424, height: 240}\n").find("v4l2.intrinsics"),
            std::string::npos);
  EXPECT_NE(message("source: replay\nreplay: {directory: d, playback: slow}\n").find("replay.playback"),
            std::string::npos);
  EXPECT_NE(message("source: replay\nreplay: {directory: d}\nextra: 1\n").find("extra"), std::string::npos);
  EXPECT_NE(message("source: replay\nreplay: {directory: d}\nX_ES: {rotation: [1, 1, 0, 0]}\n")
                .find("X_ES.rotation"),
            std::string::npos);
}

}  // namespace
}  // namespace cellmap
