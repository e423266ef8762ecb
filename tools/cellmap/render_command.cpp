// `cellmap render ENV.json|--domain N [--cell C] -o OUT.png|OUT.svg`: a still picture of a cell's boxes (top,
// side and perspective views) from a boxes file or a saved version, or from the live environment on DDS.
#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/transport/environment_monitor.hpp"
#include "cellmap/view/render.hpp"
#include "commands.hpp"
#include "security_options.hpp"

namespace cellmap::cli {
namespace {

struct RenderCommandOptions {
  std::string input;
  std::optional<std::uint32_t> domain;
  std::string cell;
  double timeout = 10;
  std::string output;
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

// The current snapshot of `cell` (or of the first cell heard) on `domain`: snapshots are transient local, so
// a reader that joins gets each cell's current one at once.
Environment environment_from_domain(std::uint32_t domain, const std::string& cell, double timeout,
                                    const SecurityOptions& security) {
  const dds::Participant participant(domain, security.setting());
  transport::EnvironmentMonitor monitor(participant);
  using Clock = std::chrono::steady_clock;
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
  while (Clock::now() < deadline) {
    for (const transport::EnvironmentMessage& message : monitor.take(std::chrono::milliseconds(200))) {
      const auto* env = std::get_if<Environment>(&message);
      if (env != nullptr && (cell.empty() || env->cell() == cell)) return *env;
    }
  }
  throw Error("render: no environment" + (cell.empty() ? std::string() : " of cell '" + cell + "'") +
              " on DDS domain " + std::to_string(domain) + " within " + std::to_string(timeout) +
              " s (is cellmapd running there?)");
}

void run_render(const RenderCommandOptions& options) {
  if (options.input.empty() == !options.domain)
    throw Error("render: give either ENV.json or --domain N (not both)");
  const Environment env = options.domain ? environment_from_domain(*options.domain, options.cell,
                                                                   options.timeout, options.security)
                                         : environment_from_file(options.input);
  view::render(env, options.output, options.render);
  std::cout << "wrote " << options.output << ": cell " << env.cell() << ", version " << env.version() << ", "
            << env.boxes().size() << " boxes" << std::endl;
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
  command->add_option("--timeout", options->timeout, "with --domain: seconds to wait for the environment")
      ->check(CLI::PositiveNumber);
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
