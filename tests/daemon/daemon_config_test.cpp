// SPDX-License-Identifier: Apache-2.0
#include "daemon_config.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"
#include "cellmap/sensor/v4l2_source.hpp"

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
  EXPECT_EQ(c.sources[0].kind, SourceKind::kSim);
  EXPECT_TRUE(c.sources[0].scene.empty());
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
  EXPECT_EQ(c.sources[0].scene, std::filesystem::path("/etc/cellmap/scenes/small.yaml"));
  EXPECT_EQ(c.sources[0].sensor, "kinect");  // untouched sibling key keeps its default
  EXPECT_DOUBLE_EQ(c.pipeline.segment.region_growing.gap, 0.05);
  EXPECT_EQ(c.pipeline.segment.k, 26);
}

TEST(DaemonConfigTest, ErrorsNameTheFileAndKey) {
  EXPECT_EQ(error_of("cel: x\n"), "my.yaml: cel: unknown key");
  EXPECT_EQ(error_of("cell: \"cell-*\"\n"),
            "my.yaml: cell: must not hold '*', '?' or '\\' (its DDS partition would be a pattern)");
  EXPECT_EQ(error_of("change: {margin: -1}\n").rfind("my.yaml: change.margin:", 0), 0u)
      << error_of("change: {margin: -1}\n");
  EXPECT_EQ(error_of("source: {kind: kinect}\n"),
            "my.yaml: source.kind: must be one of sim, replay, openni2, v4l2, pointcloud2, laserscan");
  EXPECT_EQ(error_of("log_level: loud\n"),
            "my.yaml: log_level: must be one of trace, debug, info, warn, error");
  EXPECT_EQ(error_of("segment: {neighbours: {kk: 3}}\n").rfind("my.yaml: segment.neighbours.kk", 0), 0u)
      << error_of("segment: {neighbours: {kk: 3}}\n");
}

TEST(DaemonConfigTest, ReadGoesOnPastEachProblemAndParseThrowsThemAll) {
  const std::string yaml =
      "log_level: loud\n"
      "cel: x\n"
      "sources:\n"
      "  - {kind: sim, sensor: kinect}\n"
      "  - {kind: sim, sensor: realsense, mount: tool}\n"
      "change: {margin: -1}\n"
      "segment: {k: 20}\n"  // read although the section before it failed: not an unknown key
      "self_filter: {enabled: false}\n";
  std::vector<std::string> problems;
  const DaemonConfig c = DaemonConfig::read(yaml, "my.yaml", "/etc/cellmap", problems);
  ASSERT_EQ(problems.size(), 4u) << ::testing::PrintToString(problems);
  EXPECT_EQ(problems[0], "my.yaml: log_level: must be one of trace, debug, info, warn, error");
  EXPECT_EQ(problems[1], "my.yaml: sources[1].mount: a simulated sensor is mounted by its scene");
  EXPECT_EQ(problems[2].rfind("my.yaml: change.margin: ", 0), 0u) << problems[2];
  EXPECT_EQ(problems[3], "my.yaml: cel: unknown key");
  ASSERT_EQ(c.sources.size(), 1u);  // the entry that read
  EXPECT_EQ(c.sources[0].sensor, "kinect");
  EXPECT_EQ(c.sources[0].key, "sources[0]");

  try {
    (void)DaemonConfig::parse(yaml, "my.yaml", "/etc/cellmap");
    FAIL() << "accepted";
  } catch (const ConfigErrors& e) {
    EXPECT_EQ(e.problems(), problems);
    EXPECT_EQ(std::string(e.what()),
              problems[0] + "; " + problems[1] + "; " + problems[2] + "; " + problems[3]);
  }
}

// Found by fuzzing: a complex key (`? gap: 0.04`) in a section merged over the defaults made the overlay
// throw yaml-cpp's conversion error, which would have ended cellmapd with an uncaught exception.
TEST(DaemonConfigTest, FuzzFindingsAreRefusedWithOneLine) {
  const std::string file = CELLMAP_SOURCE_DIR "/fuzz/regressions/daemon_config/complex_key.yaml";
  try {
    (void)DaemonConfig::load(file);
    FAIL() << file << " was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              file + ": segment.region_growing: the key at line 19 is not a plain name");
  }
}

TEST(DaemonConfigTest, SimIsTheDefaultAndCameraSettingsAreStillChecked) {
  const DaemonConfig c = DaemonConfig::parse("", "empty.yaml", ".");
  EXPECT_FALSE(c.sources[0].is_camera());
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
  EXPECT_TRUE(c.sources[0].is_camera());
  EXPECT_EQ(c.sources[0].camera.name, "wrist");
  EXPECT_DOUBLE_EQ(c.sources[0].camera.pose_tolerance, 0.02);
  EXPECT_TRUE(c.sources[0].camera.X_ES.translation().isApprox(Eigen::Vector3d(0, 0.05, 0.1)));
  EXPECT_TRUE(
      (c.sources[0].camera.X_ES.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_DOUBLE_EQ(c.sources[0].grouping.period, 2.0);
  EXPECT_EQ(c.sources[0].grouping.max_frames, 3u);
  EXPECT_DOUBLE_EQ(c.sources[0].grouping.pose_wait, 1.5);
  const auto& replay = std::get<ReplayConfig>(c.sources[0].camera.source);
  EXPECT_EQ(replay.directory, "/etc/cellmap/recordings/field");
  EXPECT_EQ(replay.playback, ReplayConfig::Playback::kFastest);
  EXPECT_EQ(replay.name, "wrist");
  EXPECT_EQ(error_of("source: {kind: replay}\n"),
            "my.yaml: source.replay.directory: is required for kind replay");
}

TEST(DaemonConfigTest, LiveCamerasTakeTheirSectionsWithDocumentedDefaults) {
  const DaemonConfig openni2 =
      DaemonConfig::parse("source: {kind: openni2, openni2: {uri: /data/a.oni}}\n", "my.yaml", ".");
  const auto& o = std::get<OpenNI2Config>(openni2.sources[0].camera.source);
  EXPECT_EQ(o.uri, "/data/a.oni");
  EXPECT_EQ(o.mode.to_string(), "640x480@30 DEPTH_1_MM");
  EXPECT_DOUBLE_EQ(o.reconnect.frame_timeout, 2.0);
  EXPECT_DOUBLE_EQ(o.reconnect.max_backoff, 10.0);

  const DaemonConfig v4l2 = DaemonConfig::parse("source: {kind: v4l2}\n", "my.yaml", ".");
  const auto& v = std::get<V4l2Config>(v4l2.sources[0].camera.source);
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

TEST(DaemonConfigTest, SourcesListCamerasOnTheToolAndFixedEachOverTheSourceDefaults) {
  const DaemonConfig c = DaemonConfig::parse(R"(
sweep_period: 0.25
sources:
  - {kind: openni2, sensor: post, mount: cell, pose: {position: [3.3, 2.3, 2.3]}, no_return_range: 4.5}
  - {kind: v4l2, sensor: wrist, mount: tool, pose: {position: [0.08, 0, 0.02]}, pose_tolerance: 0.02}
  - {kind: v4l2, sensor: side, X_ES: {position: [0, 0.1, 0]}, v4l2: {device: /dev/video4}}
)",
                                             "my.yaml", "/etc/cellmap");
  ASSERT_EQ(c.sources.size(), 3u);
  EXPECT_FALSE(c.simulated());
  EXPECT_EQ(c.sources[0].sensor, "post");
  EXPECT_EQ(c.sources[0].mount, sim::Mount::kCell);
  EXPECT_TRUE(c.sources[0].X_CS.translation().isApprox(Eigen::Vector3d(3.3, 2.3, 2.3)));
  EXPECT_EQ(c.sources[1].mount, sim::Mount::kTool);
  EXPECT_TRUE(c.sources[1].camera.X_ES.translation().isApprox(Eigen::Vector3d(0.08, 0, 0.02)));
  EXPECT_DOUBLE_EQ(c.sources[1].camera.pose_tolerance, 0.02);
  EXPECT_DOUBLE_EQ(c.sources[0].camera.pose_tolerance, 0.05);  // the built-in default
  EXPECT_DOUBLE_EQ(c.sources[0].no_return_range, 4.5);
  EXPECT_DOUBLE_EQ(c.sources[1].no_return_range, 0.0);  // the built-in default: off
  EXPECT_DOUBLE_EQ(c.sources[2].grouping.period, 0.25);
  EXPECT_EQ(c.sources[2].mount, sim::Mount::kTool);  // X_ES: the older spelling of a tool mount
  EXPECT_TRUE(c.sources[2].camera.X_ES.translation().isApprox(Eigen::Vector3d(0, 0.1, 0)));
  EXPECT_EQ(std::get<V4l2Config>(c.sources[2].camera.source).device, "/dev/video4");
  EXPECT_FALSE(c.robot.has_value());
}

TEST(DaemonConfigTest, SourcesErrorsNameTheEntryAndKey) {
  EXPECT_EQ(error_of("source: {noise: false}\nsources: [{sensor: a}]\n"),
            "my.yaml: source: give either source (one sensor) or sources (a list), not both");
  EXPECT_EQ(error_of("sources: []\n"), "my.yaml: sources: must be a non-empty list of sensors");
  EXPECT_EQ(error_of("sources: [{kind: v4l2, sensor: a, v4l2: {devise: x}}]\n"),
            "my.yaml: sources[0].v4l2.devise: unknown key");
  EXPECT_EQ(error_of("sources: [{kind: v4l2, sensor: a}, {kind: openni2, sensor: a}]\n"),
            "my.yaml: sources: sensor 'a' is named twice");
  EXPECT_EQ(error_of("sources: [{sensor: post}, {kind: v4l2, sensor: wrist}]\n"),
            "my.yaml: sources: simulated sensors and cameras cannot be mixed in one cell");
  EXPECT_EQ(error_of("sources: [{sensor: post, mount: cell, pose: {}}]\n"),
            "my.yaml: sources[0].mount: a simulated sensor is mounted by its scene");
  EXPECT_EQ(error_of("sources: [{sensor: post, no_return_range: -1}]\n"),
            "my.yaml: sources[0].no_return_range: must be in [0, 100], got -1");
  EXPECT_EQ(error_of("sources: [{kind: v4l2, sensor: a, mount: shelf}]\n"),
            "my.yaml: sources[0].mount: must be tool, cell or a pose, got 'shelf'");
  EXPECT_EQ(error_of("sources: [{kind: v4l2, sensor: a, mount: tool, pose: {}, X_ES: {}}]\n"),
            "my.yaml: sources[0].X_ES: is the older spelling of mount: tool with pose; give one of them");
}

TEST(DaemonConfigTest, RobotSectionIsTheGantryOrAUrdf) {
  const DaemonConfig gantry = DaemonConfig::parse("robot: {gantry: {lower: [0, 0, 0], upper: [3, 2, 1]}}\n",
                                                  "my.yaml", "/etc/cellmap");
  ASSERT_TRUE(gantry.robot.has_value());
  EXPECT_EQ(gantry.robot->dof(), 3);
  EXPECT_FALSE(gantry.robot->shapes().empty());  // the bridge, carriage and ram
  const DaemonConfig arm = DaemonConfig::parse(
      "robot: {urdf: {file: robots/cellmap_arm/urdf/cellmap_arm.urdf, tool_link: tool0}}\n", "my.yaml",
      CELLMAP_SOURCE_DIR "/config");
  ASSERT_TRUE(arm.robot.has_value());
  EXPECT_EQ(arm.robot->dof(), 6);
  EXPECT_GT(arm.robot->triangle_count(), 100u);
  EXPECT_EQ(error_of("robot: {scara: {}}\n"),
            "my.yaml: robot.gantry: exactly one of gantry, urdf is required");
  EXPECT_EQ(error_of("self_filter: {padding: 2}\n").rfind("my.yaml: self_filter.padding:", 0), 0u)
      << error_of("self_filter: {padding: 2}\n");
}

TEST(DaemonConfigTest, Ros2CellIsFedByAPointCloud2TopicAndPublishesToMoveItAndRviz) {
  const DaemonConfig c = DaemonConfig::load(CELLMAP_SOURCE_DIR "/config/ros2-cell.yaml");
  ASSERT_EQ(c.sources.size(), 1u);
  const SourceConfig& camera = c.sources[0];
  EXPECT_EQ(camera.kind, SourceKind::kPointCloud2);
  EXPECT_TRUE(camera.is_camera());
  EXPECT_EQ(camera.ros2.topic, "/camera/depth/points");
  EXPECT_EQ(camera.ros2.frame_id, "camera");
  EXPECT_EQ(camera.ros2.reliability, ros2::Reliability::kBestEffort);
  EXPECT_EQ(camera.mount, sim::Mount::kCell);
  EXPECT_TRUE(camera.X_CS.isApprox(Eigen::Isometry3d::Identity()));
  ASSERT_TRUE(c.pipeline.segment.workspace);
  EXPECT_TRUE(c.pipeline.segment.workspace->contains({2.9, -1.4, 1.4}));
  EXPECT_FALSE(c.pipeline.segment.workspace->contains({0.2, 0.0, 0.0}));
  ASSERT_TRUE(c.ros2.collision_objects);
  EXPECT_EQ(c.ros2.collision_objects->topic, "/collision_object");
  EXPECT_EQ(c.ros2.collision_objects->frame_id, "world");
  ASSERT_TRUE(c.ros2.markers);
  EXPECT_EQ(c.ros2.markers->topic, "/cellmap/markers");
  EXPECT_TRUE(c.ros2.joint_states.empty());
  EXPECT_TRUE(c.uses_ros2());
}

TEST(DaemonConfigTest, Ros2OutputsCarryUnknownSpaceUnlessSwitchedOff) {
  const DaemonConfig shipped = DaemonConfig::load(CELLMAP_SOURCE_DIR "/config/ros2-cell.yaml");
  ASSERT_TRUE(shipped.ros2.collision_objects && shipped.ros2.markers);
  EXPECT_TRUE(shipped.ros2.collision_objects->unknown_boxes);
  EXPECT_TRUE(shipped.ros2.markers->unknown_boxes);
  const DaemonConfig c = DaemonConfig::parse(
      "ros2:\n  collision_objects: {enabled: true, unknown_boxes: false}\n"
      "  markers: {enabled: true, unknown_boxes: false}\n",
      "off.yaml", ".");
  ASSERT_TRUE(c.ros2.collision_objects && c.ros2.markers);
  EXPECT_FALSE(c.ros2.collision_objects->unknown_boxes);
  EXPECT_FALSE(c.ros2.markers->unknown_boxes);
  EXPECT_NE(error_of("ros2: {markers: {enabled: true, unknown_boxes: some}}\n").find("unknown_boxes"),
            std::string::npos);
}

TEST(DaemonConfigTest, Ros2IsOffByDefault) {
  const DaemonConfig c = DaemonConfig::parse("", "empty.yaml", ".");
  EXPECT_FALSE(c.ros2.collision_objects);
  EXPECT_FALSE(c.ros2.markers);
  EXPECT_FALSE(c.uses_ros2());
}

TEST(DaemonConfigTest, LaserScanSourceOnTheToolWithJointStates) {
  const DaemonConfig c = DaemonConfig::parse(
      "robot: {gantry: {lower: [0, 0, 0], upper: [1, 1, 1], tool_at_zero: {position: [0, 0, 2]}}}\n"
      "sources: [{kind: laserscan, sensor: os32c, mount: tool, pose: {position: [0, 0, -0.1]},\n"
      "           laserscan: {topic: /scan, frame_id: laser, reliability: reliable, frame_timeout: 0.5}}]\n"
      "ros2: {joint_states: /joint_states}\n",
      "my.yaml", "/etc/cellmap");
  EXPECT_EQ(c.sources[0].kind, SourceKind::kLaserScan);
  EXPECT_EQ(c.sources[0].ros2.topic, "/scan");
  EXPECT_EQ(c.sources[0].ros2.reliability, ros2::Reliability::kReliable);
  EXPECT_DOUBLE_EQ(c.sources[0].ros2.frame_timeout, 0.5);
  EXPECT_EQ(c.sources[0].mount, sim::Mount::kTool);
  EXPECT_EQ(c.ros2.joint_states, "/joint_states");
}

TEST(DaemonConfigTest, Ros2ErrorsNameTheKey) {
  const std::string cloud =
      "sources: [{kind: pointcloud2, sensor: cam, mount: cell, pose: {position: [0, 0, 0]}, ";
  EXPECT_EQ(error_of(cloud + "pointcloud2: {frame_id: camera}}]\n"),
            "my.yaml: sources[0].pointcloud2.topic: is required: the ROS 2 topic of the sensor's samples");
  EXPECT_EQ(
      error_of(cloud + "pointcloud2: {topic: /points}}]\n"),
      "my.yaml: sources[0].pointcloud2.frame_id: is required: the header.frame_id of the sensor's samples");
  EXPECT_EQ(
      error_of(cloud + "pointcloud2: {topic: points, frame_id: camera}}]\n"),
      "my.yaml: sources[0].pointcloud2.topic: 'points' is not a ROS 2 topic name: it must start with '/'");
  EXPECT_EQ(error_of(cloud + "pointcloud2: {topic: /p, frame_id: c, reliability: sometimes}}]\n"),
            "my.yaml: sources[0].pointcloud2.reliability: must be best_effort or reliable");
  EXPECT_EQ(
      error_of("ros2: {markers: {enabled: true, topic: /cellmap//markers}}\n"),
      "my.yaml: ros2.markers.topic: '/cellmap//markers' is not a ROS 2 topic name: it has an empty token "
      "('//')");
  EXPECT_EQ(error_of("ros2: {joint_states: /joint_states}\n"),
            "my.yaml: ros2.joint_states: poses cameras; the simulated cell moves its robot itself");
  EXPECT_NE(error_of("ros2: {collision_objects: {enabled: true, colour: red}}\n").find("colour"),
            std::string::npos);
}

TEST(DaemonConfigTest, DdsSecurityWithRos2TopicsIsRefused) {
  const std::string expected =
      "DDS Security is on and the config uses ROS 2 topics (a pointcloud2 or laserscan source, or the ros2 "
      "section), which the cell's permissions cannot protect: turn one of them off (docs/ros2.md)";
  EXPECT_EQ(error_of("security: {directory: creds}\nros2: {markers: {enabled: true}}\n"), expected);
  DaemonConfig c = DaemonConfig::load(CELLMAP_SOURCE_DIR "/config/ros2-cell.yaml");
  c.security = security::Setting{"creds", security::Role::kDaemon};  // as --security sets it
  EXPECT_THROW(check_ros2_security(c), Error);
  c.ros2 = {};
  c.sources = DaemonConfig::parse("", "empty.yaml", ".").sources;
  EXPECT_NO_THROW(check_ros2_security(c));
}

}  // namespace
}  // namespace cellmap::daemon
