// SPDX-License-Identifier: Apache-2.0
// Depth → points and replay on three real frames of one Kinect-type sensor
// (shared/data/pcl/grabber_sequence): each frame is stored as raw 16-bit depth (TIFF, millimetres), its
// intrinsics (PCL grabber XML) and the organized cloud PCL's grabber computed from the same depth (PCD).
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>

#include <unistd.h>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/frame/pose_buffer.hpp"
#include "cellmap/sensor/depth_io.hpp"
#include "cellmap/sensor/replay_source.hpp"
#include "support/shared_data.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;

const fs::path kSequence = test::shared_data_dir() / "pcl" / "grabber_sequence";

// The three frames, by stem ("frame_20121214T142255.814212"), in time order.
std::vector<std::string> frame_stems() {
  std::vector<std::string> stems;
  for (const auto& entry : fs::directory_iterator(kSequence)) {
    if (entry.path().extension() == ".pcd") stems.push_back(entry.path().stem().string());
  }
  std::sort(stems.begin(), stems.end());
  return stems;
}

#define SKIP_WITHOUT_DATA() CELLMAP_SKIP_WITHOUT_DATA(kSequence)

TEST(GrabberSequenceTest, IntrinsicsComeFromTheXml) {
  SKIP_WITHOUT_DATA();
  const std::vector<std::string> stems = frame_stems();
  ASSERT_EQ(stems.size(), 3u);  // a loop over an empty folder would pass
  for (const std::string& stem : stems) {
    const PinholeIntrinsics k = read_pcl_intrinsics_xml((kSequence / (stem + ".xml")).string());
    EXPECT_DOUBLE_EQ(k.fx, 525.0);
    EXPECT_DOUBLE_EQ(k.fy, 525.0);
    EXPECT_DOUBLE_EQ(k.cx, 320.0);
    EXPECT_DOUBLE_EQ(k.cy, 240.0);
    EXPECT_DOUBLE_EQ(k.depth_scale, 0.001);
  }
}

TEST(GrabberSequenceTest, PointsFromDepthMatchTheRecordedClouds) {
  SKIP_WITHOUT_DATA();
  const std::vector<std::string> stems = frame_stems();
  ASSERT_EQ(stems.size(), 3u);
  double max_deviation = 0.0;
  for (const std::string& stem : stems) {
    const RawDepth raw = read_depth_image((kSequence / (stem + "_depth.tiff")).string());
    ASSERT_EQ(raw.width, 640);
    ASSERT_EQ(raw.height, 480);
    DepthImage image;
    image.intrinsics = read_pcl_intrinsics_xml((kSequence / (stem + ".xml")).string());
    image.intrinsics.width = raw.width;
    image.intrinsics.height = raw.height;
    image.intrinsics.max_range = 65.535;  // keep every return: the recorded cloud has no range cut
    image.depth = raw.depth;
    const Cloud computed = depth_to_points(image, true);

    pcl::PointCloud<pcl::PointXYZRGBA> recorded;
    ASSERT_EQ(pcl::io::loadPCDFile((kSequence / (stem + ".pcd")).string(), recorded), 0);
    ASSERT_EQ(recorded.width, computed.width);
    ASSERT_EQ(recorded.height, computed.height);

    std::size_t valid = 0, validity_mismatch = 0;
    double frame_max = 0.0;
    for (std::size_t i = 0; i < computed.size(); ++i) {
      const bool have = std::isfinite(computed[i].z);
      const bool had = std::isfinite(recorded[i].z);
      if (have != had) {
        ++validity_mismatch;
        continue;
      }
      if (!have) continue;
      ++valid;
      const double deviation =
          (computed[i].getVector3fMap().cast<double>() - recorded[i].getVector3fMap().cast<double>()).norm();
      frame_max = std::max(frame_max, deviation);
    }
    std::cout << stem << ": " << valid << " valid points, " << validity_mismatch
              << " pixels valid in one cloud only, max deviation " << frame_max * 1e3 << " mm\n";
    EXPECT_GT(valid, 100000u);
    EXPECT_EQ(validity_mismatch, 0u);
    max_deviation = std::max(max_deviation, frame_max);
  }
  std::cout << "max deviation over the three frames: " << max_deviation * 1e3 << " mm\n";
  RecordProperty("max_deviation_m", std::to_string(max_deviation));
  // Float rounding of metres near 5 m is ~0.5 µm; anything near a millimetre would be a model error.
  EXPECT_LT(max_deviation, 1e-5);
}

TEST(GrabberSequenceTest, ReplayGivesEachFrameItsRecordedPose) {
  SKIP_WITHOUT_DATA();
  const std::vector<std::string> stems = frame_stems();
  ASSERT_EQ(stems.size(), 3u);
  // A replay directory over the real frames: links to the depth images and XMLs, plus a poses file of a
  // gantry moving the tool 0.1 m along x per frame while turning 10 degrees about z; stamps from the file
  // names.
  const fs::path dir = fs::temp_directory_path() / ("cellmap_replay_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::vector<ReplayEntry> entries;
  for (std::size_t i = 0; i < stems.size(); ++i) {
    fs::create_symlink(kSequence / (stems[i] + "_depth.tiff"), dir / (stems[i] + "_depth.tiff"));
    fs::create_symlink(kSequence / (stems[i] + ".xml"), dir / (stems[i] + ".xml"));
    ReplayEntry entry;
    entry.file = stems[i] + "_depth.tiff";
    // "frame_20121214T142255.814212" → seconds within the minute: 55.814212
    entry.stamp = std::stod(stems[i].substr(stems[i].size() - 9));
    entry.X_CE = Eigen::Translation3d(0.1 * static_cast<double>(i), 0.0, 1.5) *
                 Eigen::AngleAxisd(static_cast<double>(i) * M_PI / 18, Eigen::Vector3d::UnitZ());
    entries.push_back(entry);
  }
  write_replay_poses((dir / "poses.csv").string(), entries);

  ReplayConfig config;
  config.name = "kinect";
  config.directory = dir.string();
  config.playback = ReplayConfig::Playback::kFastest;
  ReplaySource source(config);
  ASSERT_EQ(source.open().state, SourceState::kConnected) << source.status().reason;
  PoseBuffer poses(0.05);
  for (const StampedPose& pose : source.poses()) poses.push(pose);
  const Eigen::Isometry3d X_ES(Eigen::Translation3d(0.0, 0.05, 0.1));
  SensorPoser poser(X_ES);

  std::vector<Frame> frames;
  // Up to a minute per frame: the replay decodes each 640x480 TIFF at the lowest CPU priority, which a loaded
  // machine starves for seconds; the end of the recording still ends the loop at once.
  while (auto frame = source.next(std::chrono::milliseconds(60000))) {
    ASSERT_EQ(poser.attach(*frame, poses), PoseLookup::kFound);
    frames.push_back(std::move(*frame));
  }
  EXPECT_EQ(source.status().state, SourceState::kEnded);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(poser.posed(), 3u);
  EXPECT_EQ(poser.dropped(), 0u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].sensor, "kinect");
    EXPECT_DOUBLE_EQ(frames[i].stamp, entries[i].stamp);
    const Eigen::Isometry3d expected = entries[i].X_CE * X_ES;
    EXPECT_LT((frames[i].X_CS.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-12) << "frame " << i;
    ASSERT_TRUE(frames[i].depth.has_value());
    EXPECT_EQ(frames[i].depth->intrinsics.fx, 525.0);
    EXPECT_GT(frames[i].points_S.size(), 100000u);
  }
  // Sensor origin of frame 2 in the cell: X_CE(2) * (0, 0.05, 0.1).
  const Eigen::Vector3d origin = frames[2].X_CS.translation();
  const double c = std::cos(M_PI / 9), s = std::sin(M_PI / 9);
  EXPECT_NEAR(origin.x(), 0.2 - s * 0.05, 1e-12);
  EXPECT_NEAR(origin.y(), c * 0.05, 1e-12);
  EXPECT_NEAR(origin.z(), 1.6, 1e-12);
  fs::remove_all(dir);
}

TEST(GrabberSequenceTest, PngReplayOfTheRealDepthGivesTheSamePoints) {
  SKIP_WITHOUT_DATA();
  // The replay format a simulator or recorder writes (16-bit PNG + intrinsics.yaml), filled with a real
  // frame, must reproduce the points of the original TIFF exactly.
  const std::vector<std::string> stems = frame_stems();
  ASSERT_FALSE(stems.empty());
  const std::string& stem = stems.front();
  const RawDepth raw = read_depth_image((kSequence / (stem + "_depth.tiff")).string());
  const fs::path dir = fs::temp_directory_path() / ("cellmap_png_replay_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_depth_png((dir / "f0.png").string(), raw);
  write_file_atomically((dir / "intrinsics.yaml").string(),
                        "width: 640\nheight: 480\nfx: 525\nfy: 525\ncx: 320\ncy: 240\ndepth_scale: 0.001\n");
  write_replay_poses((dir / "poses.csv").string(),
                     {ReplayEntry{"f0.png", 1.0, Eigen::Isometry3d::Identity()}});
  ReplayConfig config;
  config.directory = dir.string();
  ReplaySource source(config);
  ASSERT_EQ(source.open().state, SourceState::kConnected) << source.status().reason;
  const Frame from_png = source.load(0);

  DepthImage image;
  image.intrinsics = read_pcl_intrinsics_xml((kSequence / (stem + ".xml")).string());
  image.intrinsics.width = raw.width;
  image.intrinsics.height = raw.height;
  image.intrinsics.max_depth_jump = kDefaultMaxDepthJump;  // what the replay source gives PCL's format
  image.depth = raw.depth;
  const Cloud from_tiff = depth_to_points(image);
  ASSERT_TRUE(from_png.depth.has_value());
  EXPECT_EQ(from_png.depth->depth, raw.depth);
  ASSERT_EQ(from_png.points_S.size(), from_tiff.size());
  for (std::size_t i = 0; i < from_tiff.size(); ++i) {
    ASSERT_EQ(from_png.points_S[i].getVector3fMap(), from_tiff[i].getVector3fMap()) << "point " << i;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cellmap
