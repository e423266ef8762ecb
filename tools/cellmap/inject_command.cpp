// SPDX-License-Identifier: Apache-2.0
// `cellmap inject [--domain N] [--security DIR [--role R]] add-box|remove|move ...`: edits the simulated
// scene of a running cellmapd.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>

#include "cellmap/common/error.hpp"
#include "cellmap/transport/scene_edits.hpp"
#include "cellmap/transport/topics.hpp"
#include "commands.hpp"
#include "parse.hpp"
#include "security_options.hpp"

namespace cellmap::cli {
namespace {

struct InjectOptions {
  std::uint32_t domain = 0;
  std::string cell;
  double wait = 10.0;
  std::string name;
  std::string center;
  std::string half_extents;
  double yaw = 0.0;
  SecurityOptions security;
};

Eigen::Vector3d vector3(const std::string& text, const std::string& what) {
  const std::vector<double> v = parse_numbers(text, what, {3});
  return {v[0], v[1], v[2]};
}

// A name no other injection is likely to have chosen, so the caller can refer to the obstacle later.
std::string fresh_name() {
  std::random_device random;
  std::ostringstream name;
  name << "box-" << std::hex << std::setw(8) << std::setfill('0') << (random() & 0xffffffffu);
  return name.str();
}

void send(const InjectOptions& options, transport::SceneEdit edit) {
  const dds::Participant participant(options.domain, options.security.setting());
  const std::string cell = options.cell.empty() ? transport::default_cell(participant) : options.cell;
  edit.cell = cell == transport::kEveryCell ? "" : cell;  // "": every simulating daemon
  const transport::SceneEditWriter writer(participant, cell);
  const auto wait =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(options.wait));
  if (!writer.wait_for_reader(wait)) {
    std::ostringstream reason;
    reason << "inject: no simulating cellmapd on domain " << options.domain << " within " << options.wait
           << " s";
    throw Error(reason.str());
  }
  writer.write(edit);
  if (!writer.wait_for_acks(wait)) throw Error("inject: the daemon did not acknowledge the edit");
}

}  // namespace

void add_inject_command(CLI::App& app) {
  auto options = std::make_shared<InjectOptions>();
  CLI::App* inject = app.add_subcommand("inject", "Edit the simulated scene of a running cellmapd over DDS");
  inject->add_option("--domain", options->domain, "DDS domain id")->check(CLI::Range(0, 232));
  inject->add_option("--cell", options->cell, "only this cell's daemon (default: every simulating daemon; with --security, the credentials' cell)");
  inject->add_option("--wait", options->wait, "seconds to wait for the daemon")
      ->check(CLI::NonNegativeNumber);
  add_security_options(inject, options->security, security::Role::kTool);
  inject->require_subcommand(1);

  // Each edit lets --domain, --security ... through to inject, so they may come after it too.
  CLI::App* add = inject->add_subcommand("add-box", "Add a box obstacle; prints its name")->fallthrough();
  add->add_option("--center", options->center, "X,Y,Z in the cell frame, metres")->required();
  add->add_option("--half-extents", options->half_extents, "A,B,C, metres")->required();
  add->add_option("--yaw", options->yaw, "rotation about the cell's z axis, radians");
  add->callback([options] {
    const transport::SceneEdit edit =
        transport::SceneEdit::add_box(fresh_name(), vector3(options->center, "--center"),
                                      vector3(options->half_extents, "--half-extents"), options->yaw);
    if (edit.half_extents.minCoeff() <= 0) throw Error("--half-extents: must be positive");
    send(*options, edit);
    std::cout << edit.name << std::endl;
  });

  CLI::App* remove = inject->add_subcommand("remove", "Remove an obstacle by name")->fallthrough();
  remove->add_option("--name", options->name, "obstacle name")->required();
  remove->callback([options] { send(*options, transport::SceneEdit::remove(options->name)); });

  CLI::App* move = inject->add_subcommand("move", "Move an obstacle to a new centre")->fallthrough();
  move->add_option("--name", options->name, "obstacle name")->required();
  move->add_option("--center", options->center, "X,Y,Z in the cell frame, metres")->required();
  move->callback([options] {
    send(*options, transport::SceneEdit::move(options->name, vector3(options->center, "--center")));
  });
}

}  // namespace cellmap::cli
