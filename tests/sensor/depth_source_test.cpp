// SPDX-License-Identifier: Apache-2.0
// Pure logic shared by the camera sources: depth mode negotiation, Z16 decoding, device clock mapping,
// intrinsics from a field of view and the RealSense defaults.
#include <gtest/gtest.h>

#include <cmath>

#include "cellmap/common/error.hpp"
#include "cellmap/sensor/depth_source.hpp"
#include "cellmap/sensor/openni2_source.hpp"
#include "cellmap/sensor/v4l2_source.hpp"

namespace cellmap {
namespace {

// What a RealSense D435's depth node enumerates (subset), plus its infrared Y8 stream on the same list.
std::vector<DepthMode> d435_modes() {
  return {{1280, 720, 6, "Z16"},  {1280, 720, 15, "Z16"},   {1280, 720, 30, "Z16"}, {848, 480, 30, "Z16"},
          {848, 480, 60, "Z16"},  {848, 480, 90, "Z16"},    {640, 480, 30, "Z16"},  {640, 480, 90, "Z16"},
          {848, 480, 30, "GREY"}, {640, 480, 29.97, "YUYV"}};
}

TEST(ChooseDepthModeTest, PicksTheExactSizeFormatAndRate) {
  const DepthMode mode = choose_depth_mode(d435_modes(), {848, 480, 60, "Z16"}, "/dev/video2");
  EXPECT_EQ(mode.width, 848);
  EXPECT_EQ(mode.height, 480);
  EXPECT_DOUBLE_EQ(mode.fps, 60);
  EXPECT_EQ(mode.format, "Z16");
}

TEST(ChooseDepthModeTest, ToleratesFractionalRatesAndPicksTheHighestForZero) {
  EXPECT_DOUBLE_EQ(choose_depth_mode(d435_modes(), {640, 480, 30, "YUYV"}, "cam").fps, 29.97);
  EXPECT_DOUBLE_EQ(choose_depth_mode(d435_modes(), {848, 480, 0, "Z16"}, "cam").fps, 90);
}

TEST(ChooseDepthModeTest, ErrorNamesTheDeviceAndWhatItOffers) {
  try {
    (void)choose_depth_mode(d435_modes(), {640, 480, 60, "Z16"}, "v4l2 /dev/video2");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("v4l2 /dev/video2: no mode 640x480@60 Z16"), std::string::npos) << message;
    EXPECT_NE(message.find("offers 1280x720@6 Z16"), std::string::npos) << message;
    EXPECT_NE(message.find("640x480@90 Z16"), std::string::npos) << message;
  }
  // Right size and rate but a colour format is not depth.
  EXPECT_THROW((void)choose_depth_mode({{640, 480, 30, "YUYV"}}, {640, 480, 30, "Z16"}, "x"), Error);
  EXPECT_THROW((void)choose_depth_mode({}, {640, 480, 30, "Z16"}, "x"), Error);
}

TEST(DecodeZ16Test, ReadsLittleEndianRowsAndSkipsPadding) {
  // 3×2 image, rows padded to 8 bytes; values 0x0102, 0xFFFF, 0, 1000, 1, 0x8000.
  const std::vector<std::uint8_t> bytes = {0x02, 0x01, 0xFF, 0xFF, 0x00, 0x00, 0xAA, 0xAA,
                                           0xE8, 0x03, 0x01, 0x00, 0x00, 0x80, 0xBB, 0xBB};
  const std::vector<std::uint16_t> depth = decode_z16(bytes.data(), bytes.size(), 3, 2, 8);
  EXPECT_EQ(depth, (std::vector<std::uint16_t>{0x0102, 0xFFFF, 0, 1000, 1, 0x8000}));
  // The last row's padding is not needed.
  EXPECT_EQ(decode_z16(bytes.data(), 14, 3, 2, 8), depth);
}

TEST(DecodeZ16Test, RefusesShortBuffersAndBadStrides) {
  const std::vector<std::uint8_t> bytes(16, 0);
  EXPECT_THROW((void)decode_z16(bytes.data(), 13, 3, 2, 8), Error);
  EXPECT_THROW((void)decode_z16(bytes.data(), 16, 3, 2, 5), Error);
  EXPECT_THROW((void)decode_z16(bytes.data(), 16, 0, 2, 8), Error);
}

TEST(FourccTest, PrintsTheCodeWithoutTrailingSpaces) {
  EXPECT_EQ(fourcc_to_string(0x2036315A), "Z16");  // 'Z' '1' '6' ' '
  EXPECT_EQ(fourcc_to_string(0x56595559), "YUYV");
}

TEST(DeviceClockTest, KeepsTheSmallestDelayOffset) {
  DeviceClock clock;
  // Device frames every 33 ms; host receives them 10 ms, then 4 ms, then 20 ms later (host epoch 1000 s).
  EXPECT_DOUBLE_EQ(clock.to_host(0, 1000.010), 1000.010);
  EXPECT_NEAR(clock.to_host(33000, 1000.037), 1000.037, 1e-9);  // smaller delay: offset moves to 1000.004
  EXPECT_NEAR(clock.to_host(66000, 1000.086), 1000.070, 1e-9);  // larger delay: mapped with 1000.004
  clock.reset();
  EXPECT_NEAR(clock.to_host(66000, 2000.0), 2000.0, 1e-9);
}

TEST(IntrinsicsFromFovTest, KinectFieldOfView) {
  // Kinect-class depth: 58.0° × 45.0° at 640×480 → fx = 320 / tan(29°) = 577.29, fy = 240 / tan(22.5°) =
  // 579.41.
  const PinholeIntrinsics k = intrinsics_from_fov(640, 480, 58.0 * M_PI / 180, 45.0 * M_PI / 180);
  EXPECT_NEAR(k.fx, 577.29, 0.01);
  EXPECT_NEAR(k.fy, 579.41, 0.01);
  EXPECT_DOUBLE_EQ(k.cx, 319.5);
  EXPECT_DOUBLE_EQ(k.cy, 239.5);
  EXPECT_THROW((void)intrinsics_from_fov(640, 480, 0.0, 1.0), Error);
  EXPECT_THROW((void)intrinsics_from_fov(640, 480, 1.0, M_PI), Error);
}

TEST(RealSenseDefaultsTest, KnownSizesOnly) {
  const PinholeIntrinsics k = realsense_d435_intrinsics(848, 480);
  EXPECT_EQ(k.width, 848);
  EXPECT_DOUBLE_EQ(k.cx, 424);
  EXPECT_DOUBLE_EQ(k.depth_scale, 0.001);
  EXPECT_NO_THROW(k.validate());
  EXPECT_NO_THROW((void)realsense_d435_intrinsics(640, 480));
  EXPECT_THROW((void)realsense_d435_intrinsics(424, 240), Error);
}

TEST(SourceStateTest, Names) {
  EXPECT_STREQ(to_string(SourceState::kDisconnected), "disconnected");
  EXPECT_STREQ(to_string(SourceState::kConnected), "connected");
  EXPECT_STREQ(to_string(SourceState::kError), "error");
}

}  // namespace
}  // namespace cellmap
