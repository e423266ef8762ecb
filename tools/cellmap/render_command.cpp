// SPDX-License-Identifier: Apache-2.0
// `cellmap render ENV.json|--domain N [--cell C] [--scene S] [--unknown show|hide] -o OUT.png|OUT.svg`: a
// still picture of a cell's boxes (top, side and perspective views) from a boxes file or a saved version, or
// from the live environment on DDS with the robot where the daemon last saw it; a simulated cell's true
// obstacles drawn under the boxes; unknown space grey and translucent, or left out.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/sim/scene.hpp"
#include "cellmap/transport/environment_monitor.hpp"
#include "cellmap/transport/layers.hpp"
#include "cellmap/view/render.hpp"
#include "commands.hpp"
#include "security_options.hpp"

namespace cellmap::cli {
namespace {

struct RenderCommandOptions {
  std::string input;
  std::optional<std::uint32_t> domain;
  std::string cell;
  bool robot = true;
  std::string scene;
  double timeout = 10;
  std::string output;
  std::string unknown = "show";
  view::RenderOptions render;
  SecurityOptions security;
};

// A boxes file (`cellmap segment -o`) or a version the daemon saved (environment-<v>.json: also "cell" and
// "stamp_ns").
Environment environment_from_file(const std::string& path) {
  const std::string text = read_file(path);
  const BoxSet set = box_set_from_json(text, path);
  const nlohmann::json doc = nlohmann::json::parse(text);  // valid: box_set_from_json parsed it
  const std::string cell = doc.contains("cell") && doc["cell"].is_string()
                               ? doc["cell"].get<std::string>()
                               : std::filesystem::path(path).stem().string();
  const std::int64_t stamp_ns = doc.contains("stamp_ns") && doc["stamp_ns"].is_number_integer()
                                    ? doc["stamp_ns"].get<std::int64_t>()
                                    : 0;
  return Environment(cell, set.version, stamp_ns, set.boxes);
}

struct LiveCell {
  Environment env;
  std::optional<transport::RobotLayer> robot;
};

bool of_cell(const std::string& cell, const std::string& wanted) {
  return wanted.empty() || cell == wanted;
}

// The current snapshot of `cell` (or of the first cell heard) on `domain`, and the robot's layer of that cell
// if `want_robot`: snapshots are transient local, so a reader that joins gets each cell's current one at
// once; the daemon writes the robot's layer at its next sweep once our reader is matched.
LiveCell live_cell(const RenderCommandOptions& options) {
  const dds::Participant participant(*options.domain, options.security.setting());
  const std::string cell = options.cell.empty() ? transport::default_cell(participant) : options.cell;
  transport::EnvironmentMonitor monitor(participant, cell);
  std::optional<transport::LayerReader> robot_reader;
  if (options.robot) robot_reader.emplace(participant, transport::Layer::kRobot, cell);
  std::optional<Environment> env;
  std::optional<transport::RobotLayer> robot;
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(options.timeout));
  while (Clock::now() < deadline && !(env && (robot || !robot_reader))) {
    for (const transport::EnvironmentMessage& message : monitor.take(std::chrono::milliseconds(100))) {
      const auto* snapshot = std::get_if<Environment>(&message);
      if (!env && snapshot != nullptr && of_cell(snapshot->cell(), options.cell)) env = *snapshot;
    }
    if (!robot_reader) continue;
    for (transport::LayerMessage& message : robot_reader->take()) {
      auto& layer = std::get<transport::RobotLayer>(message);
      if (of_cell(layer.cell, env ? env->cell() : options.cell)) robot = std::move(layer);
    }
  }
  if (!env)
    throw Error("render: no environment" +
                (options.cell.empty() ? std::string() : " of cell '" + options.cell + "'") +
                " on DDS domain " + std::to_string(*options.domain) + " within " +
                std::to_string(options.timeout) + " s (is cellmapd running there?)");
  if (robot && robot->cell != env->cell()) robot.reset();  // heard before the cell was known
  if (robot_reader && !robot)
    std::cerr << "render: no robot layer of cell " << env->cell() << " within " << options.timeout
              << " s; drawing the boxes alone" << std::endl;
  return {*env, robot};
}

std::vector<view::Solid> robot_solids(const transport::RobotLayer& layer) {
  std::vector<view::Solid> solids;
  for (const transport::PosedShape& shape : layer.shapes)
    solids.push_back({shape.X_CG, shape.geometry, shape.carried});
  return solids;
}

std::vector<view::Solid> obstacle_solids(const sim::Scene& scene) {
  std::vector<view::Solid> solids;
  for (const sim::Obstacle& obstacle : scene.obstacles)
    solids.push_back(
        {obstacle.X_CO, std::visit([](const auto& shape) -> LinkGeometry { return shape; }, obstacle.shape)});
  return solids;
}

void run_render(const RenderCommandOptions& options) {
  if (options.input.empty() == !options.domain)
    throw Error("render: give either ENV.json or --domain N (not both)");
  view::Overlays overlays;
  if (!options.scene.empty()) overlays.obstacles = obstacle_solids(sim::load_scene(options.scene));
  std::optional<Environment> env;
  if (options.domain) {
    LiveCell live = live_cell(options);
    if (live.robot) overlays.robot = robot_solids(*live.robot);
    env = std::move(live.env);
  } else {
    env = environment_from_file(options.input);
  }
  view::RenderOptions render = options.render;
  render.unknown = options.unknown == "show";
  view::render(*env, options.output, render, overlays);
  std::cout << "wrote " << options.output << ": cell " << env->cell() << ", version " << env->version()
            << ", " << env->boxes().size() << " boxes";
  const auto unknown = std::count_if(env->boxes().begin(), env->boxes().end(),
                                     [](const Box& box) { return box.space == BoxSpace::kUnknown; });
  if (unknown > 0) std::cout << " (" << unknown << " unknown" << (render.unknown ? "" : ", not drawn") << ")";
  if (!overlays.robot.empty()) std::cout << ", the robot (" << overlays.robot.size() << " shapes)";
  if (!overlays.obstacles.empty()) std::cout << ", " << overlays.obstacles.size() << " true obstacles";
  std::cout << std::endl;
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto options = std::make_shared<RenderCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "render", "Draw a cell's boxes (top, side and perspective views) into a PNG or an SVG");
  command
      ->add_option("ENV.json", options->input,
                   "a boxes file (cellmap segment -o) or a saved version (environment-<v>.json)")
      ->check(CLI::ExistingFile);
  command->add_option("--domain", options->domain, "render the live environment on this DDS domain")
      ->check(CLI::Range(0, 232));
  command->add_option("--cell", options->cell, "with --domain: the cell (default: the first heard)");
  command->add_flag(
      "!--no-robot", options->robot,
      "with --domain: do not wait for the robot's layer (drawn by default where the daemon saw it)");
  command
      ->add_option("--scene", options->scene,
                   "a simulated cell's scene file (e.g. config/cell.yaml): its true obstacles drawn in grey "
                   "under translucent boxes")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--timeout", options->timeout,
                   "with --domain: seconds to wait for the environment and the robot")
      ->check(CLI::PositiveNumber);
  command
      ->add_option(
          "--unknown", options->unknown,
          "unknown boxes (space no sensor has observed): show (grey, translucent, dashed outlines; the "
          "default) or hide")
      ->check(CLI::IsMember({"show", "hide"}));
  command->add_option("-o,--output", options->output, "the picture: OUT.png or OUT.svg")->required();
  command->add_option("--width", options->render.width, "pixels (default 1600)")
      ->check(CLI::Range(200, 20000));
  command->add_option("--height", options->render.height, "pixels (default 1000)")
      ->check(CLI::Range(150, 20000));
  command->add_option("--title", options->render.title, "heading (default: cell, version, boxes, stamp)");
  add_security_options(command, options->security, security::Role::kPlanner);
  command->callback([options] { run_render(*options); });
}

}  // namespace cellmap::cli
