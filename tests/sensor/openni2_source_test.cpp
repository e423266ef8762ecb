// SPDX-License-Identifier: Apache-2.0
// OpenNI2 source on this machine. No camera is plugged in here, so the tests check the no-device path (a
// clear reason, a clean disconnected status, retries with back-off). The OpenNI2 driver path itself runs on
// the "Dummy" device of Debian's OpenNI2 (libDummyDevice.so, a real OpenNI2 driver that streams a synthetic
// 320×240 DEPTH_1_MM image at 30 fps: row 0 at 2000 mm and a moving disc near 1000 mm).
#include "cellmap/sensor/openni2_source.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <algorithm>
#include <chrono>

#include <cstdio>
#include <thread>

#include "cellmap/common/error.hpp"
#include "cellmap/sensor/v4l2_source.hpp"
#include "sensor/sensor_test_util.hpp"

namespace cellmap {
namespace {

using std::chrono::milliseconds;

using test::fast_retries;

TEST(OpenNI2SourceTest, NoDeviceIsACleanDisconnectedStatusWithTheReason) {
  if (!list_openni2_devices().empty()) GTEST_SKIP() << "an OpenNI2 device is plugged in";
  OpenNI2Config config;
  config.reconnect = fast_retries();
  OpenNI2Source source(config);
  const SourceStatus status = source.open();
  EXPECT_EQ(status.state, SourceState::kDisconnected);
  EXPECT_NE(status.reason.find("openni2 first device"), std::string::npos) << status.reason;
  EXPECT_NE(status.reason.find("no devices found"), std::string::npos) << status.reason;
  EXPECT_EQ(status.reason.find('\n'), std::string::npos);
  EXPECT_EQ(status.attempts, 1u);
  // next() keeps retrying and never delivers a frame. (When the attempts are due, the back-off, is tested on
  // a clock the test drives: reconnect_test.cpp.)
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (source.status().attempts < 3 && std::chrono::steady_clock::now() < deadline)
    EXPECT_FALSE(source.next(milliseconds(20)).has_value());
  EXPECT_EQ(source.status().state, SourceState::kDisconnected);
  EXPECT_GE(source.status().attempts, 3u);
  source.close();
  EXPECT_EQ(source.status().state, SourceState::kClosed);
}

TEST(OpenNI2SourceTest, MissingRecordingIsAnError) {
  OpenNI2Config config;
  config.uri = "/nonexistent/sweep.oni";
  OpenNI2Source source(config);
  const SourceStatus status = source.open();
  EXPECT_EQ(status.state, SourceState::kError);
  EXPECT_NE(status.reason.find("/nonexistent/sweep.oni: no such recording"), std::string::npos)
      << status.reason;
}

TEST(OpenNI2SourceTest, RefusesFormatsThatAreNotDepth) {
  OpenNI2Config config;
  config.mode.format = "RGB888";
  EXPECT_THROW(OpenNI2Source{config}, Error);
}

OpenNI2Config dummy_device() {
  OpenNI2Config config;
  config.name = "dummy";
  config.uri = "Dummy";
  config.mode = DepthMode{320, 240, 30, "DEPTH_1_MM"};
  PinholeIntrinsics k;
  k.width = 320;
  k.height = 240;
  k.fx = k.fy = 285.0;
  k.cx = 159.5;
  k.cy = 119.5;
  config.intrinsics = k;
  config.reconnect = fast_retries();
  return config;
}

TEST(OpenNI2SourceTest, StreamsFromARealOpenNI2Driver) {
  OpenNI2Config config = dummy_device();
  // Streaming, not reconnecting (SilentDeviceTurnsDisconnectedAndIsReopened): a loaded machine's pause
  // between two frames must not reopen the device, which would restart its stamps.
  config.reconnect.frame_timeout = 60.0;
  OpenNI2Source source(config);
  const double before_open = realtime_seconds();
  ASSERT_EQ(source.open().state, SourceState::kConnected) << source.status().reason;
  std::vector<Frame> frames;
  // Three frames, however long a loaded machine takes: only a failing test waits out the minute.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (frames.size() < 3 && std::chrono::steady_clock::now() < deadline) {
    if (auto frame = source.next(milliseconds(200))) frames.push_back(std::move(*frame));
  }
  ASSERT_EQ(frames.size(), 3u) << source.status().reason;
  for (const Frame& frame : frames) {
    EXPECT_EQ(frame.sensor, "dummy");
    ASSERT_TRUE(frame.depth.has_value());
    EXPECT_EQ(frame.depth->intrinsics.width, 320);
    // Row 0 is 2000 mm across the image: 320 points at z = 2 m, y = (0 - 119.5) * 2 / 285.
    int row0 = 0;
    for (int u = 0; u < 320; ++u) row0 += frame.depth->depth[u] == 2000;
    EXPECT_EQ(row0, 320);
    // Every 2 m pixel is a point but those next to the nearer disc (the flying-pixel filter, on by default:
    // a neighbour nearer by more than 2 % of 2 m).
    const std::vector<std::uint16_t>& depth = frame.depth->depth;
    int expected_far = 0;
    for (int v = 0; v < 240; ++v) {
      for (int u = 0; u < 320; ++u) {
        if (depth[static_cast<std::size_t>(v) * 320 + u] != 2000) continue;
        bool behind = false;
        for (int nv = std::max(0, v - 1); nv <= std::min(239, v + 1); ++nv) {
          for (int nu = std::max(0, u - 1); nu <= std::min(319, u + 1); ++nu) {
            const std::uint16_t q = depth[static_cast<std::size_t>(nv) * 320 + nu];
            behind = behind || (q != 0 && q < 2000 - 40);
          }
        }
        expected_far += behind ? 0 : 1;
      }
    }
    int far = 0;
    for (const auto& p : frame.points_S) far += p.z == 2.0f ? 1 : 0;
    EXPECT_EQ(far, expected_far);
    EXPECT_GT(expected_far, 300);
    EXPECT_GT(frame.points_S.size(), 320u);  // plus the disc near 1 m
  }
  // Device stamps (33 ms apart) mapped to the host's realtime clock; the mapping's offset only shrinks, so
  // mapped stamps are never farther apart than the device's (DeviceClockTest checks the mapping on given
  // arrival times; how much it shrinks here depends on the delivery delays of a loaded machine).
  EXPECT_LE(frames[2].stamp - frames[1].stamp, 0.033 + 1e-6);
  EXPECT_GT(frames[2].stamp, frames[1].stamp);
  // On the host's realtime clock: the first frame after open() is stamped when it arrived.
  EXPECT_GE(frames[0].stamp, before_open);
  EXPECT_LE(frames[0].stamp, realtime_seconds());
  EXPECT_EQ(source.status().frames, 3u);
  source.close();
  EXPECT_EQ(source.status().state, SourceState::kClosed);
}

// gcc defines __SANITIZE_ADDRESS__ under -fsanitize=address; clang 14 (the sanitizer pass) answers only
// __has_feature(address_sanitizer).
#if defined(__SANITIZE_ADDRESS__)
#define CELLMAP_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CELLMAP_UNDER_ASAN 1
#endif
#endif

TEST(OpenNI2SourceTest, SilentDeviceTurnsDisconnectedAndIsReopened) {
#ifdef CELLMAP_UNDER_ASAN
  // Under ASan about one run in four crashes inside OpenNI2 itself (SEGV near null in libOpenNI2, on the
  // DummyDevice driver's frame thread, during the fast close/reopen cycles below), also with a 200 ms wait
  // after stopping the stream; the release pass runs it.
  GTEST_SKIP()
      << "the DummyDevice driver's frame thread crashes inside OpenNI2 under ASan (release pass runs this)";
#endif
  // The Dummy device sends a frame every 33 ms; a 10 ms frame timeout makes each gap look like an unplugged
  // camera, so the real driver goes through disconnect → back-off → reopen → frames again.
  OpenNI2Config config = dummy_device();
  config.reconnect.frame_timeout = 0.010;
  config.reconnect.initial_backoff = 0.005;
  config.reconnect.max_backoff = 0.010;
  OpenNI2Source source(config);
  ASSERT_EQ(source.open().state, SourceState::kConnected) << source.status().reason;
  // Until it was disconnected, reopened and delivered again, however long a loaded machine takes: only a
  // failing test waits out the minute. (Frames before the first disconnect do not count: a loaded machine may
  // read two before the first gap.)
  bool saw_disconnect = false;
  std::uint64_t frames_before_disconnect = 0;
  const auto reopened_and_streaming = [&] {
    return saw_disconnect && source.status().attempts >= 2 &&
           source.status().frames > frames_before_disconnect;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline && !reopened_and_streaming()) {
    (void)source.next(milliseconds(5));
    if (source.status().state == SourceState::kDisconnected) {
      if (!saw_disconnect) frames_before_disconnect = source.status().frames;
      saw_disconnect = true;
      EXPECT_EQ(source.status().reason, "no frames for 0.01 s");
    }
  }
  EXPECT_TRUE(saw_disconnect);
  EXPECT_GE(source.status().attempts, 2u);
  EXPECT_GT(source.status().frames, frames_before_disconnect) << "no frame after the reopen";
}

TEST(OpenNI2SourceTest, ModeTheDeviceDoesNotOfferIsAnErrorListingWhatItOffers) {
  OpenNI2Config config = dummy_device();
  config.mode = DepthMode{640, 480, 30, "DEPTH_1_MM"};
  config.intrinsics.reset();
  OpenNI2Source source(config);
  const SourceStatus status = source.open();
  EXPECT_EQ(status.state, SourceState::kError);
  EXPECT_NE(status.reason.find("no mode 640x480@30 DEPTH_1_MM; offers 320x240@30 DEPTH_1_MM"),
            std::string::npos)
      << status.reason;
  EXPECT_FALSE(source.next(milliseconds(1)).has_value());
}

TEST(OpenNI2SourceTest, DeviceWithoutFieldOfViewNeedsConfiguredIntrinsics) {
  OpenNI2Config config = dummy_device();
  config.intrinsics.reset();
  OpenNI2Source source(config);
  const SourceStatus status = source.open();
  EXPECT_EQ(status.state, SourceState::kError);
  EXPECT_NE(status.reason.find("reports no field of view"), std::string::npos) << status.reason;
}

// Runs `cellmap sensors ARGS`; returns the exit status and stdout + stderr.
std::pair<int, std::string> run_sensors_command(const std::string& args) {
  const std::string command = std::string(CELLMAP_TOOL) + " sensors " + args + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  std::string output;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

TEST(ProbeOpenNI2DeviceTest, ListsTheModesOfANamedDevice) {
  const DepthDeviceInfo info = probe_openni2_device("Dummy");
  EXPECT_EQ(info.driver, "openni2");
  EXPECT_EQ(info.uri, "Dummy");
  EXPECT_EQ(describe_modes(info.modes), "320x240@30 DEPTH_1_MM");
  try {
    (void)probe_openni2_device("/nonexistent/sweep.oni");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "openni2 /nonexistent/sweep.oni: no such recording");
  }
}

TEST(SensorsCommandTest, ProbesAUriAndFailsInOneLine) {
  const auto [status, output] = run_sensors_command("--openni2-uri Dummy");
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("OpenNI2 devices opened by URI: 1 device\n  Dummy  Table Tennis"), std::string::npos)
      << output;
  EXPECT_NE(output.find("    320x240@30 DEPTH_1_MM\n"), std::string::npos) << output;
  EXPECT_EQ(output.find("No depth sensors found."), std::string::npos) << output;
  const auto [bad_status, bad_output] = run_sensors_command("--openni2-uri /nonexistent/sweep.oni");
  EXPECT_EQ(bad_status, 1);
  EXPECT_EQ(bad_output.rfind("cellmap: openni2 /nonexistent/sweep.oni: no such recording\n", 0), 0u)
      << bad_output;
}

TEST(SensorsCommandTest, ListsAndExitsZero) {
  const auto [status, output] = run_sensors_command("");
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("OpenNI2 depth devices:"), std::string::npos) << output;
  EXPECT_NE(output.find("V4L2 depth devices (Z16) in /dev:"), std::string::npos) << output;
  if (list_openni2_devices().empty() && list_v4l2_devices().empty()) {
    EXPECT_NE(output.find("No depth sensors found."), std::string::npos) << output;
  }
}

}  // namespace
}  // namespace cellmap
