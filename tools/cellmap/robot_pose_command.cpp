// SPDX-License-Identifier: Apache-2.0
// `cellmap robot-pose --cell C (--pose X,Y,Z[,QW,QX,QY,QZ] | --joints NAME=V,...|V1,V2,... [--payload ...])
// [--rate HZ] [--duration S]`: publishes a standing robot's tool pose on cellmap/robot_state, or its joint
// positions (and what the tool holds) on cellmap/robot_joints, stamped with the current time, as a robot
// controller would. Brings up a mounted camera on a desk with the robot standing still.
#include <chrono>
#include <cmath>
#include <functional>
#include <iostream>
#include <sstream>
#include <thread>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "cellmap/transport/robot_joints.hpp"
#include "cellmap/transport/robot_state.hpp"
#include "commands.hpp"
#include "parse.hpp"
#include "security_options.hpp"

namespace cellmap::cli {
namespace {

struct RobotPoseOptions {
  std::uint32_t domain = 0;
  std::string cell;
  std::string pose;
  std::string joints;
  std::string payload;
  double rate = 100.0;
  double duration = 10.0;
  double wait = 10.0;
  SecurityOptions security;
};

Eigen::Quaterniond unit_quaternion(const std::vector<double>& v, std::size_t first, const std::string& what) {
  const Eigen::Quaterniond q(v[first], v[first + 1], v[first + 2], v[first + 3]);
  if (std::abs(q.norm() - 1.0) > 1e-3)
    throw Error(what + ": the rotation must be a unit quaternion qw,qx,qy,qz");
  return q.normalized();
}

transport::RobotState tool_pose(const RobotPoseOptions& options) {
  const std::vector<double> v = parse_numbers(options.pose, "--pose", {3, 7});
  transport::RobotState state;
  state.cell = options.cell;
  state.X_CE.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  if (v.size() == 7) state.X_CE.linear() = unit_quaternion(v, 3, "--pose").toRotationMatrix();
  return state;
}

// "a=1,b=2" (named) or "1,2" (in the robot's joint order).
transport::RobotJoints joint_positions(const RobotPoseOptions& options) {
  transport::RobotJoints joints;
  joints.cell = options.cell;
  const std::vector<std::string> items = split(options.joints, ',');
  const bool named = options.joints.find('=') != std::string::npos;
  for (const std::string& item : items) {
    const std::size_t eq = item.find('=');
    if (named != (eq != std::string::npos)) {
      throw Error("--joints: give every joint as NAME=VALUE, or only values in the robot's joint order");
    }
    if (named) {
      if (eq == 0) throw Error("--joints: a joint name is empty in '" + item + "'");
      joints.names.push_back(item.substr(0, eq));
    }
    joints.positions.push_back(parse_finite(named ? item.substr(eq + 1) : item, "--joints"));
  }
  if (!options.payload.empty()) {
    const std::vector<double> v = parse_numbers(options.payload, "--payload", {6, 10});
    Payload payload;
    payload.X_EB.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    payload.half_extents = Eigen::Vector3d(v[3], v[4], v[5]);
    if (payload.half_extents.minCoeff() < 0) throw Error("--payload: half extents must be >= 0");
    if (v.size() == 10) payload.X_EB.linear() = unit_quaternion(v, 6, "--payload").toRotationMatrix();
    joints.payload = payload;
  }
  return joints;
}

std::chrono::nanoseconds seconds(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
}

// Calls send(stamp_ns) at the rate for the duration; returns how many were sent.
std::uint64_t repeat(const RobotPoseOptions& options, const std::function<void(std::int64_t)>& send) {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(seconds(1.0 / options.rate));
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(seconds(options.duration));
  std::uint64_t sent = 0;
  for (auto next = Clock::now(); options.duration == 0 || next < end; next += period) {
    std::this_thread::sleep_until(next);
    send(wall_clock_ns());
    ++sent;
  }
  return sent;
}

// `what`: "poses" or "joint states", as the messages and the summary line name them.
template <class Writer, class Message>
void publish_on(const RobotPoseOptions& options, Message message, const std::string& what) {
  const dds::Participant participant(options.domain, options.security.setting());
  const Writer writer(participant, options.cell);
  if (!writer.wait_for_reader(seconds(options.wait))) {
    std::ostringstream reason;  // the wait as given ("1 s", not "1.000000 s")
    reason << "robot-pose: no cellmapd reading robot " << what << " on domain " << options.domain
           << " within " << options.wait << " s";
    throw Error(reason.str());
  }
  const std::uint64_t sent = repeat(options, [&](std::int64_t stamp_ns) {
    message.stamp_ns = stamp_ns;
    writer.write(message);
  });
  if (!writer.wait_for_acks(seconds(options.wait))) {
    throw Error("robot-pose: the daemon did not acknowledge the " + what);
  }
  std::cout << "sent " << sent << " " << what << std::endl;
}

void publish(const RobotPoseOptions& options) {
  if (options.pose.empty() == options.joints.empty())
    throw Error("robot-pose: give exactly one of --pose, --joints");
  if (!options.payload.empty() && options.joints.empty()) throw Error("--payload: only with --joints");
  if (!options.pose.empty()) {
    publish_on<transport::RobotStateWriter>(options, tool_pose(options), "poses");
  } else {
    publish_on<transport::RobotJointsWriter>(options, joint_positions(options), "joint states");
  }
}

}  // namespace

void add_robot_pose_command(CLI::App& app) {
  auto options = std::make_shared<RobotPoseOptions>();
  CLI::App* command = app.add_subcommand(
      "robot-pose",
      "Publish a standing robot's tool pose (cellmap/robot_state) or joint positions (cellmap/robot_joints), "
      "stamped now, at a rate");
  command->add_option("--domain", options->domain, "DDS domain id")->check(CLI::Range(0, 232));
  command->add_option("--cell", options->cell, "the cell id of the daemon")->required();
  command->add_option("--pose", options->pose, "X,Y,Z[,QW,QX,QY,QZ]: X_CE, metres and a unit quaternion");
  command->add_option(
      "--joints", options->joints,
      "NAME=VALUE,... or V1,V2,... (the robot's joint order): joint positions, metres or radians");
  command->add_option(
      "--payload", options->payload,
      "CX,CY,CZ,HX,HY,HZ[,QW,QX,QY,QZ]: a box the tool holds (centre, half extents, rotation in "
      "the tool frame; with --joints)");
  command->add_option("--rate", options->rate, "samples per second")->check(CLI::Range(0.1, 10000.0));
  command->add_option("--duration", options->duration, "seconds to publish (0 = until interrupted)")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--wait", options->wait, "seconds to wait for a daemon")->check(CLI::NonNegativeNumber);
  add_security_options(command, options->security, security::Role::kRobot);
  command->callback([options] { publish(*options); });
}

}  // namespace cellmap::cli
