// cellmapd's camera input on the real OpenNI2 driver path (Debian's Dummy device, 320x240 at 30 fps) with a
// frame timeout shorter than its frame interval: every gap looks like an unplugged camera, so the input goes
// through streaming → disconnected → reopened with back-off → streaming, and never fuses a frame without a
// robot pose. Labelled e2e: it loads the OpenNI2 drivers (whose own allocations LeakSanitizer would report).
#include "camera_input.hpp"

#include <gtest/gtest.h>

#include <set>

#include "transport/loopback.hpp"

namespace cellmap::daemon {
namespace {

TEST(CameraInputTest, DisconnectsReopensAndDropsFramesWithoutAPose) {
  test::use_loopback();
  const dds::Participant participant(186);
  DaemonConfig config = DaemonConfig::parse(
      "source:\n  kind: openni2\n  sensor: wrist\n  pose_wait: 0.05\n  openni2: {uri: Dummy, width: 320, "
      "height: 240, intrinsics: {fx: 285, fy: 285, cx: 159.5, cy: 119.5}, frame_timeout: 0.01, reconnect: "
      "{initial_backoff: 0.05, max_backoff: 0.05}}\n",
      "test.yaml", ".");
  CameraInput camera(config.source, participant, "cell");
  ASSERT_EQ(camera.open().state, SourceState::kConnected) << camera.sensor_state();
  std::vector<std::string> states{camera.sensor_state()};
  std::size_t sweeps = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (std::chrono::steady_clock::now() < until) {
    sweeps += camera.step(std::chrono::milliseconds(20)).size();
    if (camera.sensor_state() != states.back()) states.push_back(camera.sensor_state());
  }
  // streaming, disconnected, streaming again, … : reopened after each loss.
  ASSERT_GE(states.size(), 3u);
  EXPECT_EQ(states[0], "streaming");
  EXPECT_EQ(states[1].rfind("disconnected: ", 0), 0u) << states[1];
  EXPECT_NE(states[1].find("no frames for 0.01 s"), std::string::npos) << states[1];
  EXPECT_EQ(states[2], "streaming");
  EXPECT_GE(camera.status().attempts, 2u);
  // No robot pose ever arrived: every frame was dropped, none fused.
  EXPECT_EQ(sweeps, 0u);
  EXPECT_GT(camera.dropped_frames(), 0u);
  EXPECT_EQ(camera.poses_received(), 0u);
}

}  // namespace
}  // namespace cellmap::daemon
