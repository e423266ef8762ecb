// SPDX-License-Identifier: Apache-2.0
// Test helper for the DDS Security end-to-end tests: one participant, of one role or without credentials, in
// a process of its own (Cyclone DDS takes one security setting per domain and process).
//
//   security_probe DOMAIN CELL writers [--security DIR --role R]
//     tries to create each of cellmap's writers and readers; prints one JSON object: name -> "created" or
//     "refused", then exits.
//   security_probe DOMAIN CELL serve [--publish] [--security DIR --role R]
//     what a daemon reads: scene edits and the cell's robot poses (and with --publish it publishes version 1
//     of the cell with one box). Prints "ready", then {"edits": E, "poses": P} whenever a count changes; on
//     SIGTERM one more line with "subscribers" (readers matched to its environment now) and
//     "subscribers_joined" (ever) and exits.
//   security_probe DOMAIN CELL forge FROM_VERSION ID,ID,... [--security DIR --role R]
//     the attack: a delta from FROM_VERSION removing the ids, a snapshot of an empty cell, and every 100 ms a
//     scene edit and a robot pose. Prints "forging"; on SIGTERM {"reached_environment": bool,
//     "reached_edits": bool, "reached_poses": bool} (whether any reader matched) and exits.
//   security_probe DOMAIN CELL spy SECONDS [--security DIR --role R]
//     readers of the environment, its deltas and the status for SECONDS; prints {"received": N}.
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "cellmap/transport/environment_monitor.hpp"
#include "cellmap/transport/environment_publisher.hpp"
#include "cellmap/transport/environment_subscriber.hpp"
#include "cellmap/transport/robot_state.hpp"
#include "cellmap/transport/scene_edits.hpp"
#include "cellmap/transport/status_reader.hpp"

namespace {

using namespace cellmap;
using namespace std::chrono_literals;
using nlohmann::json;

// True once SIGTERM (blocked in main) is pending.
bool terminated() {
  sigset_t term;
  sigemptyset(&term);
  sigaddset(&term, SIGTERM);
  const timespec none{0, 0};
  return sigtimedwait(&term, nullptr, &none) == SIGTERM;
}

std::string attempt(const std::function<void()>& create) {
  try {
    create();
    return "created";
  } catch (const Error& e) {
    return std::string(e.what()).find("Not Allowed By Security") != std::string::npos ? "refused" : e.what();
  }
}

void writers(const dds::Participant& p, const std::string& cell) {
  json result;
  result["environment_publisher"] = attempt([&] { transport::EnvironmentPublisher x(p, cell); });
  result["scene_edit_writer"] = attempt([&] { transport::SceneEditWriter x(p, cell); });
  result["robot_state_writer"] = attempt([&] { transport::RobotStateWriter x(p, cell); });
  result["environment_subscriber"] = attempt([&] { transport::EnvironmentSubscriber x(p, cell); });
  result["status_reader"] = attempt([&] { transport::StatusReader x(p, cell); });
  result["scene_edit_reader"] = attempt([&] { transport::SceneEditReader x(p, cell); });
  result["robot_state_reader"] = attempt([&] { transport::RobotStateReader x(p, cell); });
  // Outside the cell's partition: another cell's, and every cell's.
  result["other_cell_subscriber"] = attempt([&] { transport::EnvironmentSubscriber x(p, cell + "-other"); });
  result["every_cell_status_reader"] = attempt([&] { transport::StatusReader x(p, transport::kEveryCell); });
  result["every_cell_scene_edit_writer"] =
      attempt([&] { transport::SceneEditWriter x(p, transport::kEveryCell); });
  std::cout << result.dump() << std::endl;
}

void serve(const dds::Participant& p, const std::string& cell, bool publish) {
  transport::SceneEditReader edits(p, cell);
  transport::RobotStateReader poses(p, cell);
  std::optional<transport::EnvironmentPublisher> publisher;
  if (publish) {
    publisher.emplace(p, cell);
    Box box;
    box.id = 1;
    box.half_extents = Eigen::Vector3d::Constant(0.1);
    publisher->publish(Environment(cell, 1, wall_clock_ns(), {box}));
  }
  std::cout << "ready" << std::endl;
  std::size_t edit_count = 0;
  std::size_t pose_count = 0;
  while (!terminated()) {
    const std::size_t before = edit_count + pose_count;
    edit_count += edits.take(50ms).size();
    pose_count += poses.take(50ms).size();
    if (edit_count + pose_count != before)
      std::cout << json{{"edits", edit_count}, {"poses", pose_count}}.dump() << std::endl;
  }
  json last{{"edits", edit_count}, {"poses", pose_count}};
  if (publisher) {
    int subscribers = 0;
    while (publisher->wait_for_subscribers(static_cast<std::uint32_t>(subscribers + 1), 0s)) ++subscribers;
    last["subscribers"] = subscribers;
    last["subscribers_joined"] = publisher->subscribers_joined();
  }
  std::cout << last.dump() << std::endl;
}

void forge(const dds::Participant& p, const std::string& cell, std::uint64_t from, const std::string& ids) {
  transport::EnvironmentPublisher publisher(p, cell);
  EnvironmentDelta wipe{cell, from, from + 1, wall_clock_ns(), {}, {}, {}};
  for (const std::string& id : split(ids, ',')) wipe.removed.push_back(std::stoull(id));
  publisher.publish(Environment(cell, from + 1, wall_clock_ns(), {}), wipe);
  publisher.publish(Environment(cell, from + 2, wall_clock_ns(), {}));
  const transport::SceneEditWriter edits(p, cell);
  const transport::RobotStateWriter poses(p, cell);
  transport::SceneEdit edit;
  edit.cell = cell;
  edit.name = "forged";
  edit.center = Eigen::Vector3d(2.12, 0.45, 0.9);
  edit.half_extents = Eigen::Vector3d(0.1, 0.1, 0.15);
  transport::RobotState pose;
  pose.cell = cell;
  pose.X_CE.translation() = Eigen::Vector3d(1.0, 1.0, 1.0);
  std::cout << "forging" << std::endl;
  while (!terminated()) {
    edits.write(edit);
    pose.stamp_ns = wall_clock_ns();
    poses.write(pose);
    std::this_thread::sleep_for(100ms);
  }
  std::cout << json{{"reached_environment", publisher.wait_for_subscribers(1, 0s)},
                    {"reached_edits", edits.wait_for_reader(0s)},
                    {"reached_poses", poses.wait_for_reader(0s)}}
                   .dump()
            << std::endl;
}

// Separate from forge: a participant's readers match its own writers.
void spy(const dds::Participant& p, double seconds) {
  transport::EnvironmentMonitor monitor(p);
  transport::StatusReader status(p);
  std::size_t received = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end)
    received += monitor.take(100ms).size() + status.take().size();
  std::cout << json{{"received", received}}.dump() << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  std::optional<security::Setting> security;
  const auto flag = std::find(args.begin(), args.end(), "--security");
  const bool flags_ok = flag == args.end() || (args.end() - flag == 4 && flag[2] == "--role");
  if (flags_ok && flag != args.end()) {
    security = security::Setting{flag[1], security::parse_role(flag[3])};
    args.erase(flag, args.end());
  }
  if (!flags_ok || args.size() < 3) {
    std::cerr << "usage: security_probe DOMAIN CELL writers|serve [--publish]|forge FROM IDS|spy SECONDS "
                 "[--security DIR --role R]\n";
    return 2;
  }
  sigset_t term;
  sigemptyset(&term);
  sigaddset(&term, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &term, nullptr);  // before any DDS thread: SIGTERM is taken by terminated()
  try {
    const dds::Participant participant(static_cast<std::uint32_t>(std::stoul(args[0])), security);
    const std::string& cell = args[1];
    if (args[2] == "writers") writers(participant, cell);
    if (args[2] == "serve") serve(participant, cell, args.size() > 3 && args[3] == "--publish");
    if (args[2] == "forge" && args.size() == 5) forge(participant, cell, std::stoull(args[3]), args[4]);
    if (args[2] == "spy" && args.size() == 4) spy(participant, std::stod(args[3]));
  } catch (const std::exception& e) {
    std::cerr << "security_probe: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
