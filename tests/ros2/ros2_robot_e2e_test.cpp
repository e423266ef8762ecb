// SPDX-License-Identifier: Apache-2.0
// cellmapd fed by ROS 2 sensor drivers on a moving robot, all through a ROS 2 node of another DDS vendor
// (Fast DDS: tests/ros2/peer): the arm cell's fixed camera with the arm's joints only on /joint_states
// (ros2_control's joint_state_broadcaster), and the default cell's gantry sweeping a 2D lidar whose scans
// come as sensor_msgs/msg/LaserScan, as the paper's OS32C did. The scenes are rendered by cellmap's simulator
// and played in real time, stamped on the wall clock as drivers stamp them.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <random>

#include "cellmap/common/wall_clock.hpp"
#include "cellmap/sim/simulator.hpp"
#include "daemon/service_e2e.hpp"
#include "ros2/ros2_peer.hpp"
#include "support/dds_domains.hpp"

namespace cellmap {
namespace {

using namespace std::chrono_literals;

// A daemon of `config_yaml` on `domain` in a state directory of its own, and a planner following it.
struct RunningDaemon {
  RunningDaemon(const std::string& config_yaml, int domain, const std::string& cell)
      : participant(static_cast<std::uint32_t>(domain)), planner(participant, cell), status(participant) {
    const std::filesystem::path config = dir.path() / "cellmapd.yaml";
    std::ofstream(config) << config_yaml;
    daemon = std::make_unique<test::ChildProcess>(
        std::vector<std::string>{CELLMAPD, "--config", config.string(), "--domain", std::to_string(domain),
                                 "--state-dir", (dir.path() / "state").string()});
  }
  test::TempDir dir;
  dds::Participant participant;
  transport::EnvironmentSubscriber planner;
  transport::StatusReader status;
  std::unique_ptr<test::ChildProcess> daemon;
};

// Plays `publish(t)` for scene times t = 0, step, 2·step, ... each at its moment of the wall clock (t after
// the start), until `done()`; returns the stamp (ns) of scene time 0.
template <typename Publish, typename Done>
std::int64_t play(double step, Publish&& publish, Done&& done) {
  const std::int64_t start_ns = wall_clock_ns();
  const auto start = std::chrono::steady_clock::now();
  for (double t = 0.0; !done(); t += step) {
    publish(t, start_ns);
    std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(t + step)));
  }
  return start_ns;
}

std::int64_t stamp_of(std::int64_t start_ns, double t) {
  return start_ns + static_cast<std::int64_t>(t * 1e9);
}

std::vector<Eigen::Vector3f> as_floats(const Cloud& cloud) {
  std::vector<Eigen::Vector3f> points;
  for (const pcl::PointXYZ& p : cloud) points.push_back(p.getVector3fMap());
  return points;
}

// The arm cell (config/arm-cell.yaml's scene): its post camera's frames as PointCloud2 on /post/depth/points,
// the arm's joints only on /joint_states, in a shuffled order and with a gripper's joint the model lacks.
TEST(Ros2RobotE2eTest, ArmCellWithItsJointsOnlyOnJointStatesMakesOneVersion) {
  test::use_loopback();
  const std::uint64_t sweeps = 120;
  const std::string scene_file = CELLMAP_SOURCE_DIR "/config/scenes/arm_cell.yaml";
  const sim::Scene scene = sim::load_scene(scene_file);
  const int post = scene.find_sensor("post");
  const Eigen::Isometry3d& X_CS = scene.sensors[std::size_t(post)].X_CS;
  const Eigen::Quaterniond q_CS(X_CS.linear());
  std::ostringstream yaml;
  yaml << "cell: arm\nsweep_period: 0.5\nstatus_period: 0.5\nsegment: {boxes: {kind: aabb}}\n"
       << "change: {gather_sweeps: 2}\n"
       << "robot: {urdf: {file: " CELLMAP_SOURCE_DIR "/config/robots/cellmap_arm/urdf/cellmap_arm.urdf, "
       << "tool_link: tool0, base: {position: [1.5, -0.45, 0.5], rotation: [0.7071067811865476, 0, 0, "
          "0.7071067811865476]}}}\n"
       << "sources: [{kind: pointcloud2, sensor: post, mount: cell, pose: {position: ["
       << X_CS.translation().x() << ", " << X_CS.translation().y() << ", " << X_CS.translation().z()
       << "], rotation: [" << q_CS.w() << ", " << q_CS.x() << ", " << q_CS.y() << ", " << q_CS.z() << "]}, "
       << "pointcloud2: {topic: /post/depth/points, frame_id: post_depth_optical_frame}}]\n"
       << "ros2: {joint_states: /joint_states}\n";
  const int domain = test::domain::kRos2ArmJointStates;
  test::Ros2Peer peer(domain);
  RunningDaemon cell(yaml.str(), domain, "arm");

  sim::SimOptions options;  // noise on, as config/arm-cell.yaml has it
  const sim::Simulator simulator(scene, options);
  std::vector<std::string> names = scene.robot.joint_names();
  names.push_back("gripper_finger");
  std::reverse(names.begin(), names.end());
  std::uint64_t processed = 0;
  std::vector<Environment> versions;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60 + sweeps * 2);
  play(
      0.1,
      [&](double t, std::int64_t start_ns) {
        const sim::SimWindow window = simulator.window(t, t + 0.1, {post});
        for (const JointState& joints : window.joints) {
          std::vector<double> q(joints.q.data(), joints.q.data() + joints.q.size());
          q.push_back(0.02);
          std::reverse(q.begin(), q.end());
          peer.publish_joints("/joint_states", names, q, stamp_of(start_ns, joints.stamp));
        }
        for (const sim::SimFrame& frame : window.frames) {
          const std::vector<Eigen::Vector3f> points = as_floats(frame.frame.points_S);
          peer.publish_cloud("/post/depth/points", "post_depth_optical_frame", std::uint32_t(points.size()),
                             1, points, stamp_of(start_ns, frame.frame.stamp));
        }
        for (const transport::CellStatus& s : cell.status.take(0ms)) {
          if (s.cell == "arm") processed = std::max(processed, s.sweeps);
        }
      },
      [&] { return processed >= sweeps || std::chrono::steady_clock::now() > deadline; });
  EXPECT_GE(processed, sweeps) << "cellmapd processed only " << processed << " sweeps";
  const std::optional<Environment> env = cell.planner.environment();
  ASSERT_TRUE(env) << "no version in " << processed << " sweeps";
  EXPECT_EQ(env->version(), 1u) << "the moving arm made versions";
  EXPECT_GT(env->boxes().size(), 5u);
  std::cout << "arm cell over ROS 2 (PointCloud2 + JointState): " << processed << " sweeps, version "
            << env->version() << ", " << env->boxes().size() << " boxes\n";
}

// What the scanner sees of each obstacle in one pass of the gantry: the exact hit points, by obstacle name.
std::map<std::string, std::vector<Eigen::Vector3d>> seen_per_obstacle(const sim::Scene& scene, int scanner) {
  sim::SimOptions exact;
  exact.noise = false;
  const sim::Simulator simulator(scene, exact);
  std::map<std::string, std::vector<Eigen::Vector3d>> seen;
  for (const sim::SimFrame& frame : simulator.sweep(scanner)) {
    const sim::LineScanner& fan = scene.sensors[std::size_t(scanner)].scanner;
    for (std::size_t i = 0; i < frame.exact.size(); ++i) {
      if (frame.exact[i] <= 0.0 || frame.hit[i] < 0) continue;
      const double angle = -fan.fov / 2 + fan.fov * double(i) / double(fan.beams - 1);
      const Eigen::Vector3d p_S(std::cos(angle) * frame.exact[i], std::sin(angle) * frame.exact[i], 0.0);
      seen[scene.obstacles[std::size_t(frame.hit[i])].name].push_back(frame.frame.X_CS * p_S);
    }
  }
  return seen;
}

// The default cell (config/cell.yaml): the gantry carries the OS32C, whose scans come as LaserScan on /scan,
// the gantry's joints as JointState on /joint_states; one pass of its 151 stops every 1.5 s.
TEST(Ros2RobotE2eTest, GantrySweepingALaserScanBuildsBoxesHoldingEveryObstacleTheCamerasBox) {
  test::use_loopback();
  const sim::Scene scene = sim::load_scene(CELLMAP_SOURCE_DIR "/config/cell.yaml");
  const int scanner = scene.find_sensor("os32c");
  const sim::SensorSpec& spec = scene.sensors[std::size_t(scanner)];
  const Eigen::Quaterniond q_ES(spec.X_ES.linear());
  std::ostringstream yaml;
  yaml << "cell: gantry-scan\nsweep_period: 1.51\nstatus_period: 0.5\nchange: {settle_sweeps: 3}\n"
       << "robot: {gantry: {lower: [0.0, 0.0, -0.6], upper: [3.0, 2.0, 0.0], "
       << "tool_at_zero: {position: [0.0, 0.0, 2.4], rotation: [0, 1, 0, 0]}}}\n"
       << "sources: [{kind: laserscan, sensor: os32c, mount: tool, pose: {position: ["
       << spec.X_ES.translation().x() << ", " << spec.X_ES.translation().y() << ", "
       << spec.X_ES.translation().z() << "], rotation: [" << q_ES.w() << ", " << q_ES.x() << ", " << q_ES.y()
       << ", " << q_ES.z() << "]}, "
       << "laserscan: {topic: /scan, frame_id: laser}}]\n"
       << "ros2: {joint_states: /joint_states}\n";
  const int domain = test::domain::kRos2GantryLaserScan;
  test::Ros2Peer peer(domain);
  RunningDaemon cell(yaml.str(), domain, "gantry-scan");

  sim::SimOptions exact;
  exact.noise = false;
  exact.render_robot = false;
  const sim::Simulator simulator(scene, exact);
  const sim::SweepPlan& plan = scene.plan_for(spec);
  const float increment = float(spec.scanner.fov / (spec.scanner.beams - 1));
  std::size_t stop = 0;
  std::optional<transport::CellStatus> settled;
  std::optional<transport::CellStatus> first_report;
  play(
      0.01,
      [&](double t, std::int64_t start_ns) {
        const Eigen::VectorXd& q = plan.stops[stop % plan.stops.size()];
        const std::vector<double> joints(q.data(), q.data() + q.size());
        const std::int64_t stamp = stamp_of(start_ns, t);
        const sim::SimFrame frame =
            simulator.render(scanner, q, t, stop / plan.stops.size(), stop % plan.stops.size());
        std::vector<float> ranges;
        for (const double r : frame.exact)
          ranges.push_back(r > 0.0 ? float(r) : std::numeric_limits<float>::infinity());
        // The controller's samples bracket the scan's stamp (the gantry stands at the stop meanwhile).
        peer.publish_joints("/joint_states", {"x", "y", "z"}, joints, stamp - 2'000'000);
        peer.publish_scan("/scan", "laser", float(-spec.scanner.fov / 2), increment,
                          float(spec.scanner.min_range), float(spec.scanner.max_range), ranges, stamp);
        peer.publish_joints("/joint_states", {"x", "y", "z"}, joints, stamp + 2'000'000);
        ++stop;
        for (const transport::CellStatus& s : cell.status.take(0ms)) {
          if (s.cell != "gantry-scan" || s.version == 0) continue;
          if (!first_report || s.version != first_report->version) first_report = s;
          if (s.sweeps >= first_report->sweeps + 4) settled = s;
        }
      },
      [&] { return settled.has_value() || stop > 151 * 60; });
  ASSERT_TRUE(settled) << "no settled version after " << stop << " scans";
  ASSERT_TRUE(cell.planner.wait_for_version(settled->version, test::kDaemonPatience));
  const Environment env = *cell.planner.environment();
  EXPECT_EQ(env.version(), 1u);

  // Every obstacle the scanner sees is held whole by the boxes: each of its exact hit points lies in a box.
  const std::map<std::string, std::vector<Eigen::Vector3d>> seen = seen_per_obstacle(scene, scanner);
  for (const char* obstacle : {"table_top", "pallet_a", "pallet_b", "carton", "fixture_plate", "fixture_tip",
                               "stack_1", "stack_3", "drum", "ball"}) {
    ASSERT_EQ(seen.count(obstacle), 1u) << obstacle << " is not in the scanner's view";
    std::size_t held = 0;
    for (const Eigen::Vector3d& p : seen.at(obstacle)) {
      held += std::any_of(env.boxes().begin(), env.boxes().end(),
                          [&](const Box& b) { return b.contains(p, 0.021); });
    }
    EXPECT_EQ(held, seen.at(obstacle).size())
        << obstacle << ": " << held << " of " << seen.at(obstacle).size() << " seen points in a box";
  }
  std::cout << "default cell, gantry with a LaserScan over ROS 2: version " << env.version() << ", "
            << env.boxes().size() << " boxes\n";
}

}  // namespace
}  // namespace cellmap
