// SPDX-License-Identifier: Apache-2.0
// Depth image files and replay directories, on files the test writes itself.
#include "cellmap/sensor/replay_source.hpp"

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/sensor/depth_io.hpp"
#include "sensor/sensor_test_util.hpp"
#include "support/manual_clock.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

using test::ManualClock;
using test::ramp;
using test::TempDir;

// How long a test waits for a frame that is due: the reader thread reads it at the lowest CPU priority, which
// a loaded machine (or a sanitizer) can make slow. Only a failing test waits that long. The tests of when
// frames are due play on a ManualClock, which stands still while they wait for a read.
constexpr std::chrono::milliseconds kReadWait{60000};

// Seconds from `start` to now on `clock`.
double seconds_since(const ManualClock& clock, SteadyClock::time_point start) {
  return std::chrono::duration<double>(clock.now() - start).count();
}

// A replay directory: two PNG depth frames with intrinsics.yaml and one PCD frame.
struct Recording {
  TempDir dir{"replay"};
  std::vector<ReplayEntry> entries;
  Recording() {
    // The ramp's rows lie 0.3 m behind each other: the flying-pixel filter (on by default) is off here.
    write_file_atomically(dir / "intrinsics.yaml",
                          "width: 6\nheight: 4\nfx: 3\nfy: 3\ncx: 2.5\ncy: 1.5\nmax_depth_jump: 0\n");
    write_depth_png(dir / "f0.png", ramp(6, 4));
    write_depth_png(dir / "f1.png", ramp(6, 4));
    Cloud cloud;
    cloud.push_back(pcl::PointXYZ(0.1f, 0.2f, 1.0f));
    cloud.push_back(pcl::PointXYZ(std::nanf(""), 0.f, 0.f));
    cloud.push_back(pcl::PointXYZ(-0.1f, 0.0f, 2.0f));
    pcl::io::savePCDFileBinary(dir / "f2.pcd", cloud);
    for (int i = 0; i < 3; ++i) {
      ReplayEntry entry;
      entry.file = i < 2 ? "f" + std::to_string(i) + ".png" : "f2.pcd";
      entry.stamp = 100.0 + 0.05 * i;
      entry.X_CE = Eigen::Translation3d(i, 0, 1) * Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitY());
      entries.push_back(entry);
    }
    write_replay_poses(dir / "poses.csv", entries);
  }
};

TEST(ReplayPosesTest, RoundTripAndStrictParsing) {
  Recording recording;
  const std::vector<ReplayEntry> back = read_replay_poses(recording.dir / "poses.csv");
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].file, recording.entries[i].file);
    EXPECT_DOUBLE_EQ(back[i].stamp, recording.entries[i].stamp);
    EXPECT_TRUE(back[i].X_CE.isApprox(recording.entries[i].X_CE, 1e-12));
  }
  const std::string header = "file,stamp,x,y,z,qw,qx,qy,qz\n";
  write_file_atomically(recording.dir / "a.csv", "file,stamp,x,y,z,qx,qy,qz,qw\nf0.png,1,0,0,0,1,0,0,0\n");
  EXPECT_THROW((void)read_replay_poses(recording.dir / "a.csv"), Error);  // wrong header
  write_file_atomically(recording.dir / "b.csv", header + "f0.png,1,0,0,0,2,0,0,0\n");
  EXPECT_THROW((void)read_replay_poses(recording.dir / "b.csv"), Error);  // not a unit quaternion
  write_file_atomically(recording.dir / "c.csv", header + "f0.png,1,0,0,0,1,0,0,0\nf1.png,1,0,0,0,1,0,0,0\n");
  EXPECT_THROW((void)read_replay_poses(recording.dir / "c.csv"), Error);  // stamp not increasing
  write_file_atomically(recording.dir / "d.csv", header + "f0.png,1,0,nan,0,1,0,0,0\n");
  try {
    (void)read_replay_poses(recording.dir / "d.csv");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("d.csv:2: y"), std::string::npos) << e.what();
  }
}

TEST(ReplaySourceTest, PlaysDepthImagesAndCloudsInOrder) {
  Recording recording;
  ReplayConfig config;
  config.name = "desk";
  config.directory = recording.dir.path().string();
  config.playback = ReplayConfig::Playback::kFastest;
  ReplaySource source(config);
  ASSERT_EQ(source.open().state, SourceState::kConnected) << source.status().reason;
  EXPECT_EQ(source.poses().size(), 3u);

  auto f0 = source.next(kReadWait);
  ASSERT_TRUE(f0.has_value());
  EXPECT_EQ(f0->sensor, "desk");
  EXPECT_DOUBLE_EQ(f0->stamp, 100.0);
  ASSERT_TRUE(f0->depth.has_value());
  EXPECT_EQ(f0->points_S.size(), 6u * 4u - 4u);  // column 0 holds no return
  // Pixel (1, 0): z = 1.001 m, x = (1 - 2.5) z / 3.
  EXPECT_FLOAT_EQ(f0->points_S[0].z, 1.001f);
  EXPECT_FLOAT_EQ(f0->points_S[0].x, static_cast<float>(-1.5 * 1.001 / 3));
  ASSERT_TRUE(source.next(kReadWait).has_value());
  auto f2 = source.next(kReadWait);
  ASSERT_TRUE(f2.has_value());
  EXPECT_FALSE(f2->depth.has_value());
  EXPECT_EQ(f2->points_S.size(), 2u);  // the NaN point is skipped
  EXPECT_FALSE(source.next(std::chrono::milliseconds(10)).has_value());
  EXPECT_EQ(source.status().state, SourceState::kEnded);
  EXPECT_EQ(source.status().frames, 3u);
}

// Frame i is due i / rate_hz after the source opened, and next() hands it out then: not before (a shorter
// wait returns nothing after waiting its time), not later. On a clock the test drives, so a slow read or a
// loaded machine cannot make a frame look early or late.
TEST(ReplaySourceTest, FixedRateSpacesTheFrames) {
  Recording recording;
  ReplayConfig config;
  config.directory = recording.dir.path().string();
  config.playback = ReplayConfig::Playback::kFixed;
  config.rate_hz = 20.0;  // 50 ms apart
  ManualClock clock;
  ReplaySource source(config, clock);
  const SteadyClock::time_point start = clock.now();
  ASSERT_EQ(source.open().state, SourceState::kConnected);
  ASSERT_TRUE(source.next(kReadWait).has_value());
  EXPECT_EQ(seconds_since(clock, start), 0.0) << "frame 0 is due when the source opens";
  EXPECT_FALSE(source.next(1ms).has_value()) << "frame 1 is not due for 50 ms";
  EXPECT_NEAR(seconds_since(clock, start), 0.001, 1e-9) << "a wait that ends before the frame is due";
  ASSERT_TRUE(source.next(kReadWait).has_value());
  EXPECT_NEAR(seconds_since(clock, start), 0.050, 1e-9);
  ASSERT_TRUE(source.next(kReadWait).has_value());
  EXPECT_NEAR(seconds_since(clock, start), 0.100, 1e-9);
  EXPECT_FALSE(source.next(kReadWait).has_value());
  EXPECT_EQ(source.status().state, SourceState::kEnded);
}

// The next frame's file is read while the source waits for its time, so a frame is not late by its
// decoding: once it was read, the file may go and the frame still comes, with its points.
TEST(ReplaySourceTest, ReadsTheNextFrameAheadOfItsTime) {
  Recording recording;
  ReplayConfig config;
  config.directory = recording.dir.path().string();
  config.playback = ReplayConfig::Playback::kFixed;
  config.rate_hz = 1.0;
  ManualClock clock;  // stands still while the test waits for the read: frame 1 stays a second ahead
  ReplaySource source(config, clock);
  const SteadyClock::time_point start = clock.now();
  ASSERT_EQ(source.open().state, SourceState::kConnected);
  ASSERT_TRUE(source.next(kReadWait).has_value());
  EXPECT_FALSE(source.next(1ms).has_value());  // frame 1 is due in a second
  const auto give_up = std::chrono::steady_clock::now() + kReadWait;
  while (!source.next_frame_read() && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(1ms);
  ASSERT_TRUE(source.next_frame_read()) << "frame 1 was not read ahead";
  EXPECT_LT(seconds_since(clock, start), 1.0) << "read ahead means before it is due";
  fs::remove(recording.dir.path() / "f1.png");
  const std::optional<Frame> f1 = source.next(kReadWait);
  ASSERT_TRUE(f1.has_value()) << source.status().reason;
  EXPECT_NEAR(seconds_since(clock, start), 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(f1->stamp, 100.05);
  EXPECT_EQ(f1->points_S.size(), 6u * 4u - 4u);
  EXPECT_EQ(source.status().state, SourceState::kConnected);
}

// Replays given one start play on that clock, not from when each opened: the first frame is due at the
// start, the second at its recorded interval after it.
TEST(ReplaySourceTest, AGivenStartIsWhenTheFirstFrameIsDue) {
  Recording recording;
  ReplayConfig config;
  config.directory = recording.dir.path().string();
  ManualClock clock;
  const SteadyClock::time_point start = clock.now() + 300ms;
  config.start = start;
  ReplaySource source(config, clock);
  ASSERT_EQ(source.open().state, SourceState::kConnected);
  EXPECT_FALSE(source.next(1ms).has_value()) << "not due for 300 ms";
  ASSERT_TRUE(source.next(kReadWait).has_value());
  EXPECT_EQ(seconds_since(clock, start), 0.0);
  ASSERT_TRUE(source.next(kReadWait).has_value());
  EXPECT_NEAR(seconds_since(clock, start), 0.050, 1e-6);  // the recorded interval (stamps 100 and 100.05)
}

TEST(ReplaySourceTest, BrokenRecordingsAreErrorsNamingTheProblem) {
  Recording recording;
  ReplayConfig config;
  config.directory = (recording.dir.path() / "absent").string();
  ReplaySource missing(config);
  EXPECT_EQ(missing.open().state, SourceState::kError);
  EXPECT_NE(missing.status().reason.find("no such replay directory"), std::string::npos);
  EXPECT_FALSE(missing.next(std::chrono::milliseconds(1)).has_value());

  fs::remove(recording.dir.path() / "f1.png");
  config.directory = recording.dir.path().string();
  ReplaySource lost_frame(config);
  EXPECT_EQ(lost_frame.open().state, SourceState::kError);
  EXPECT_NE(lost_frame.status().reason.find("f1.png: no such frame"), std::string::npos)
      << lost_frame.status().reason;

  fs::remove(recording.dir.path() / "intrinsics.yaml");
  write_depth_png(recording.dir / "f1.png", ramp(6, 4));
  ReplaySource no_intrinsics(config);
  ASSERT_EQ(no_intrinsics.open().state, SourceState::kConnected);
  EXPECT_THROW((void)no_intrinsics.load(0), Error);
  EXPECT_FALSE(no_intrinsics.next(kReadWait).has_value());  // the read's outcome
  EXPECT_EQ(no_intrinsics.status().state, SourceState::kError);
  EXPECT_NE(no_intrinsics.status().reason.find("no intrinsics"), std::string::npos);
}

// A PCD frame whose header claims what the file cannot hold (here a COUNT past 32 bits, which once made the
// reader spin) stops the replay at that frame with the loader's one-line reason; an all-NaN frame is a frame.
TEST(ReplaySourceTest, PcdFramesGoThroughTheHardenedLoader) {
  Recording recording;
  ReplayConfig config;
  config.directory = recording.dir.path().string();
  config.playback = ReplayConfig::Playback::kFastest;
  Cloud nothing;
  nothing.push_back(pcl::PointXYZ(std::nanf(""), 0.f, 0.f));
  pcl::io::savePCDFileBinary(recording.dir / "f1.pcd", nothing);
  write_file_atomically(recording.dir / "f2.pcd",
                        "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 4294967297\nWIDTH 1\n"
                        "HEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  recording.entries[1].file = "f1.pcd";
  write_replay_poses(recording.dir / "poses.csv", recording.entries);
  ReplaySource source(config);
  ASSERT_EQ(source.open().state, SourceState::kConnected);
  ASSERT_TRUE(source.next(kReadWait).has_value());
  const std::optional<Frame> empty = source.next(kReadWait);
  ASSERT_TRUE(empty.has_value());
  EXPECT_TRUE(empty->points_S.empty());
  EXPECT_FALSE(source.next(kReadWait).has_value());
  EXPECT_EQ(source.status().state, SourceState::kError);
  EXPECT_EQ(source.status().reason,
            recording.dir / "f2.pcd" + ": COUNT: '4294967297' is not an integer in [0, 65536]");
}

}  // namespace
}  // namespace cellmap
