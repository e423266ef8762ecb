// SPDX-License-Identifier: Apache-2.0
#pragma once
// Every DDS domain id the tests use, in one table. ctest runs tests side by side (-j 2) and DDS tests on
// loopback talk to whatever joins the same domain, so each test that starts participants has ids of its own.
// A new test takes a free id here. Ids used elsewhere: benchmarks 140-143 (bench/dds_bench.cpp), 144
// (bench/daemon_bench.cpp) and 145 (bench/ros2_bench.cpp), the browser test 220-221
// (tests/view/view_browser_test.py), the Python module's tests 213 and 215 (tests/python), scripts/soak 179, the install tests 172 and 198
// (tests/install).
// Credentials tests name domains 7, 197 and 233 without joining them. Ids above 232 cannot be joined:
// Cyclone's ports for domain d start at 7400 + 250 · d, beyond 65535 there.

namespace cellmap::test::domain {

// ros2 peer: ros2_peer_test, the Fast DDS stand-in for a ROS 2 node (tests/ros2/peer) against plain Cyclone.
inline constexpr int kPeerPublishes = 60;
inline constexpr int kPeerSubscribes = 61;
inline constexpr int kPeerLateMarkers = 62;
inline constexpr int kPeerBigCloud = 63;
inline constexpr int kPeerBestEffort = 64;

// transport_test: in-process publisher and subscribers.
inline constexpr int kEveryVersion = 110;
inline constexpr int kLateJoiner = 111;
inline constexpr int kWholeVersion = 112;
inline constexpr int kSlowSubscriber = 113;
inline constexpr int kPublisherRestart = 114;
inline constexpr int kCellsShareADomain = 115;
inline constexpr int kMonitor = 116;
inline constexpr int kSceneEdits = 117;
inline constexpr int kPublisherRefuses = 118;
inline constexpr int kStatusLateReader = 119;
inline constexpr int kSecuritySetting = 124;
inline constexpr int kSecuritySettingOther = 126;
inline constexpr int kSampleSizeCap = 127;
inline constexpr int kSampleSizeUserCap = 128;
inline constexpr int kLayerLimits = 129;

// transport_e2e_test: the publisher helper and `cellmap echo` as processes.
inline constexpr int kLateJoinerProcess = 121;
inline constexpr int kKilledPublisher = 122;
inline constexpr int kFallsBehind = 123;
inline constexpr int kForgedAhead = 125;

// robot_joints_test, robot_state_test (`cellmap robot-pose` and `inject` as processes).
inline constexpr int kJointsInOrder = 100;
inline constexpr int kJointsRefused = 101;
inline constexpr int kJointsCommand = 102;
inline constexpr int kPosesInOrder = 180;
inline constexpr int kPosesRejected = 181;
inline constexpr int kPoseCommand = 185;
inline constexpr int kNobodyListening = 204;  // nobody joins it: the tools must say so

// cellmapd_e2e_test (Secure*: the same tests with DDS Security on).
inline constexpr int kAddRemove = 150;
inline constexpr int kRestart = 151;
inline constexpr int kSecureAddRemove = 190;
inline constexpr int kSecureRestart = 191;
inline constexpr int kReload = 200;
inline constexpr int kResume = 203;
inline constexpr int kMailbox = 205;
inline constexpr int kGatherRestart = 214;

// status_command_e2e_test: `cellmap status` against cellmapd (cellmap_cli_test's daemon-less run uses
// kNobodyListening).
inline constexpr int kStatusCommand = 206;

// planner_e2e_test.
inline constexpr int kPlanner = 170;
inline constexpr int kKill = 171;
inline constexpr int kSecurePlanner = 192;
inline constexpr int kPlannerUnknown = 217;  // environments published by the test, unknown boxes in them
inline constexpr int kPlannerHidden = 227;   // cellmapd: an object under a shelf, then in view

// camera_e2e_test.
inline constexpr int kUnplugged = 162;
inline constexpr int kJointsCamera = 163;
inline constexpr int kReplay = 182;
inline constexpr int kNoDevice = 183;
inline constexpr int kRobotPose = 184;
inline constexpr int kReplayEnded = 201;
inline constexpr int kReplayError = 202;

// working_cell_e2e_test: the arm cell's daemon, self filter on and off, and the coverage of each camera.
inline constexpr int kArmFiltered = 160;
inline constexpr int kArmUnfiltered = 161;
inline constexpr int kArmPostCoverage = 164;
inline constexpr int kArmWristCoverage = 165;
inline constexpr int kArmBothCoverage = 166;

// daemon_test: the daemon's parts in process.
inline constexpr int kKeeper = 186;
inline constexpr int kSimAcquisition = 187;
// layer_publisher_test: one domain per test, since ctest runs them side by side.
inline constexpr int kVoxelLayerPublisher = 223;
inline constexpr int kRegionLayerPublisher = 224;
inline constexpr int kSensorLayerPublisher = 225;
inline constexpr int kRobotLayerPublisher = 137;
inline constexpr int kNoRobotLayerPublisher = 226;

// faults_e2e_test.
inline constexpr int kFirstVersionFault = 188;
inline constexpr int kLaterVersionFault = 189;
inline constexpr int kSecureFirstVersionFault = 211;
inline constexpr int kSecureRefusedWrite = 212;

// security_e2e_test.
inline constexpr int kPlainPlant = 209;
inline constexpr int kSecurePlant = 210;
inline constexpr int kAttack = 193;
inline constexpr int kRoles = 194;
inline constexpr int kOtherCa = 195;
inline constexpr int kRefusal = 196;
inline constexpr int kRevoked = 228;

// transport_test: the viewer's layers.
inline constexpr int kLayers = 222;
inline constexpr int kRobotLayer = 136;

// daemon_bench_test: `cellmap bench daemon` at a low rate (its subscriber in a process of its own).
inline constexpr int kBenchDaemon = 230;

// plant_bench_test: `cellmap bench plant` with two cells (218 is also the benchmark's default; 219 is kept
// for a second plant run beside it).
inline constexpr int kBenchPlant = 219;

// ros2_bench_test: `cellmap bench ros2` for a second per input variant (its writers mostly in a child
// process).
inline constexpr int kBenchRos2 = 70;

// ros2_dds_test: the ROS 2 sources and writers in process.
inline constexpr int kRos2PointCloud = 65;
inline constexpr int kRos2LaserScan = 66;
inline constexpr int kRos2JointStates = 67;
inline constexpr int kRos2CollisionObjects = 68;
inline constexpr int kRos2Markers = 69;
inline constexpr int kRos2UnknownObjects = 74;
inline constexpr int kRos2UnknownMarkers = 75;

// ros2_e2e_test: cellmapd with a ROS 2 node of another vendor (tests/ros2/peer).
inline constexpr int kRos2Cell = 71;
inline constexpr int kRos2ArmJointStates = 72;
inline constexpr int kRos2GantryLaserScan = 73;

}  // namespace cellmap::test::domain
