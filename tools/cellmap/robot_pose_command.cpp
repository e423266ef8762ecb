// `cellmap robot-pose --cell C --pose X,Y,Z[,QW,QX,QY,QZ] [--rate HZ] [--duration S]`: publishes a tool pose
// on cellmap/robot_state, stamped with the current time, as a robot controller would. Brings up a mounted
// camera on a desk with the robot standing still.
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>

#include "cellmap/common/error.hpp"
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
  double rate = 100.0;
  double duration = 10.0;
  double wait = 10.0;
  SecurityOptions security;
};

void publish(const RobotPoseOptions& options) {
  const std::vector<double> v = parse_numbers(options.pose, "--pose", {3, 7});
  transport::RobotState state;
  state.cell = options.cell;
  state.X_CE.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  if (v.size() == 7) {
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-3)
      throw Error("--pose: the rotation must be a unit quaternion qw,qx,qy,qz");
    state.X_CE.linear() = q.normalized().toRotationMatrix();
  }
  const dds::Participant participant(options.domain, options.security.setting());
  const transport::RobotStateWriter writer(participant);
  const auto wait =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(options.wait));
  if (!writer.wait_for_reader(wait)) {
    throw Error("robot-pose: no cellmapd reading robot poses on domain " + std::to_string(options.domain) +
                " within " + std::to_string(options.wait) + " s");
  }
  using Clock = std::chrono::steady_clock;
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / options.rate));
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(options.duration));
  std::uint64_t sent = 0;
  for (auto next = Clock::now(); options.duration == 0 || next < end; next += period) {
    std::this_thread::sleep_until(next);
    state.stamp_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count();
    writer.write(state);
    ++sent;
  }
  if (!writer.wait_for_acks(wait)) throw Error("robot-pose: the daemon did not acknowledge the poses");
  std::cout << "sent " << sent << " poses" << std::endl;
}

}  // namespace

void add_robot_pose_command(CLI::App& app) {
  auto options = std::make_shared<RobotPoseOptions>();
  CLI::App* command = app.add_subcommand(
      "robot-pose", "Publish a standing robot's tool pose on cellmap/robot_state (stamped now), at a rate");
  command->add_option("--domain", options->domain, "DDS domain id")->check(CLI::Range(0, 232));
  command->add_option("--cell", options->cell, "the cell id of the daemon")->required();
  command->add_option("--pose", options->pose, "X,Y,Z[,QW,QX,QY,QZ]: X_CE, metres and a unit quaternion")
      ->required();
  command->add_option("--rate", options->rate, "poses per second")->check(CLI::Range(0.1, 10000.0));
  command->add_option("--duration", options->duration, "seconds to publish (0 = until interrupted)")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--wait", options->wait, "seconds to wait for a daemon")->check(CLI::NonNegativeNumber);
  add_security_options(command, options->security, security::Role::kRobot);
  command->callback([options] { publish(*options); });
}

}  // namespace cellmap::cli
