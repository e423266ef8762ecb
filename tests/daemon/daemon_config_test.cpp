#include "daemon_config.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap::daemon {
namespace {

std::string error_of(const std::string& yaml) {
  try {
    (void)DaemonConfig::parse(yaml, "my.yaml", "/etc/cellmap");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(DaemonConfigTest, BuiltInDefaultsAreTheShippedFile) {
  const DaemonConfig c = DaemonConfig::parse("", "empty.yaml", ".");
  EXPECT_EQ(c.cell, "cell-1");
  EXPECT_EQ(c.source.kind, SourceKind::kSim);
  EXPECT_TRUE(c.source.scene.empty());
  EXPECT_DOUBLE_EQ(c.pipeline.occupancy.resolution, 0.02);
  EXPECT_EQ(c.pipeline.change.persist_sweeps, 3);
  // The voxel-tuned segmentation of config/cellmapd.yaml, not the batch defaults of config/segment.yaml.
  EXPECT_EQ(c.pipeline.segment.k, 26);
  EXPECT_DOUBLE_EQ(c.pipeline.segment.region_growing.gap, 0.035);
}

TEST(DaemonConfigTest, FileOverlaysDefaultsKeyByKey) {
  const DaemonConfig c = DaemonConfig::parse(
      "cell: press-3\nsource: {scene: scenes/small.yaml}\nsegment: {region_growing: {gap: 0.05}}\n",
      "my.yaml", "/etc/cellmap");
  EXPECT_EQ(c.cell, "press-3");
  EXPECT_EQ(c.source.scene, std::filesystem::path("/etc/cellmap/scenes/small.yaml"));
  EXPECT_EQ(c.source.sensor, "kinect");  // untouched sibling key keeps its default
  EXPECT_DOUBLE_EQ(c.pipeline.segment.region_growing.gap, 0.05);
  EXPECT_EQ(c.pipeline.segment.k, 26);
}

TEST(DaemonConfigTest, ErrorsNameTheFileAndKey) {
  EXPECT_EQ(error_of("cel: x\n"), "my.yaml: cel: unknown key");
  EXPECT_EQ(error_of("change: {margin: -1}\n").rfind("my.yaml: change.margin:", 0), 0u)
      << error_of("change: {margin: -1}\n");
  EXPECT_EQ(error_of("source: {kind: kinect}\n"),
            "my.yaml: source.kind: must be one of sim, replay, openni2, v4l2");
  EXPECT_EQ(error_of("log_level: loud\n"),
            "my.yaml: log_level: must be one of trace, debug, info, warn, error");
  EXPECT_EQ(error_of("segment: {neighbours: {kk: 3}}\n").rfind("my.yaml: segment.neighbours.kk", 0), 0u)
      << error_of("segment: {neighbours: {kk: 3}}\n");
}

TEST(DaemonConfigTest, SimIsTheDefaultAndCameraSettingsAreStillChecked) {
  const DaemonConfig c = DaemonConfig::parse("", "empty.yaml", ".");
  EXPECT_FALSE(c.source.is_camera());
  // A misspelt key in a section the chosen kind does not use is still an error.
  EXPECT_EQ(error_of("source: {v4l2: {devise: /dev/video2}}\n"), "my.yaml: source.v4l2.devise: unknown key");
  EXPECT_EQ(error_of("source: {openni2: {format: RGB_888}}\n"),
            "my.yaml: source.openni2.format: must be DEPTH_1_MM or DEPTH_100_UM");
}

TEST(DaemonConfigTest, ReplayCameraWithExtrinsicAndGrouping) {
  const DaemonConfig c = DaemonConfig::parse(R"(
sweep_period: 2.0
source:
  kind: replay
  sensor: wrist
  X_ES: {translation: [0, 0.05, 0.1], rotation: [0.7071067811865476, 0, 0, 0.7071067811865476]}
  pose_tolerance: 0.02
  pose_wait: 1.5
  sweep_frames: 3
  replay: {directory: recordings/field, playback: fastest}
)",
                                             "my.yaml", "/etc/cellmap");
  EXPECT_TRUE(c.source.is_camera());
  EXPECT_EQ(c.source.camera.name, "wrist");
  EXPECT_DOUBLE_EQ(c.source.camera.pose_tolerance, 0.02);
  EXPECT_TRUE(c.source.camera.X_ES.translation().isApprox(Eigen::Vector3d(0, 0.05, 0.1)));
  EXPECT_TRUE((c.source.camera.X_ES.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_DOUBLE_EQ(c.source.grouping.period, 2.0);
  EXPECT_EQ(c.source.grouping.max_frames, 3u);
  EXPECT_DOUBLE_EQ(c.source.grouping.pose_wait, 1.5);
  const auto& replay = std::get<ReplayConfig>(c.source.camera.source);
  EXPECT_EQ(replay.directory, "/etc/cellmap/recordings/field");
  EXPECT_EQ(replay.playback, ReplayConfig::Playback::kFastest);
  EXPECT_EQ(replay.name, "wrist");
  EXPECT_EQ(error_of("source: {kind: replay}\n"),
            "my.yaml: source.replay.directory: is required for kind replay");
}

TEST(DaemonConfigTest, LiveCamerasTakeTheirSectionsWithDocumentedDefaults) {
  const DaemonConfig openni2 =
      DaemonConfig::parse("source: {kind: openni2, openni2: {uri: /data/a.oni}}\n", "my.yaml", ".");
  const auto& o = std::get<OpenNI2Config>(openni2.source.camera.source);
  EXPECT_EQ(o.uri, "/data/a.oni");
  EXPECT_EQ(o.mode.to_string(), "640x480@30 DEPTH_1_MM");
  EXPECT_DOUBLE_EQ(o.reconnect.frame_timeout, 2.0);
  EXPECT_DOUBLE_EQ(o.reconnect.max_backoff, 10.0);

  const DaemonConfig v4l2 = DaemonConfig::parse("source: {kind: v4l2}\n", "my.yaml", ".");
  const auto& v = std::get<V4l2Config>(v4l2.source.camera.source);
  EXPECT_EQ(v.device, "/dev/video0");
  EXPECT_EQ(v.mode.to_string(), "848x480@30 Z16");
  ASSERT_TRUE(v.intrinsics.has_value());
  EXPECT_DOUBLE_EQ(v.intrinsics->fx, realsense_d435_intrinsics(848, 480).fx);  // D435 defaults
  EXPECT_DOUBLE_EQ(v.intrinsics->depth_scale, 0.001);
  EXPECT_DOUBLE_EQ(v.intrinsics->min_range, 0.3);
  EXPECT_EQ(error_of("source: {kind: v4l2, v4l2: {width: 320, height: 240}}\n")
                .rfind("my.yaml: source.v4l2.intrinsics:", 0),
            0u);
}

TEST(DaemonConfigTest, SecurityIsOffByDefaultAndItsDirectoryIsRelativeToTheFile) {
  EXPECT_FALSE(DaemonConfig::parse("", "empty.yaml", ".").security.has_value());
  const DaemonConfig c =
      DaemonConfig::parse("security: {directory: keys/cell-1}\n", "my.yaml", "/etc/cellmap");
  ASSERT_TRUE(c.security.has_value());
  EXPECT_EQ(c.security->directory, std::filesystem::path("/etc/cellmap/keys/cell-1"));
  EXPECT_EQ(c.security->role, security::Role::kDaemon);
  EXPECT_EQ(error_of("security: {directory: k, role: admin}\n"),
            "my.yaml: security.role: must be one of daemon, planner, robot, tool");
  EXPECT_EQ(error_of("security: {dir: k}\n"), "my.yaml: security.dir: unknown key");
}

}  // namespace
}  // namespace cellmap::daemon
