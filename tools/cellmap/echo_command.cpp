// SPDX-License-Identifier: Apache-2.0
// `cellmap echo [--domain N] [--cell C] [--count K] [--timeout SEC] [--security DIR [--role R]]`: one JSON
// line per snapshot/delta received.
#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cellmap/common/error.hpp"
#include "cellmap/transport/environment_monitor.hpp"
#include "cellmap/transport/topics.hpp"
#include "commands.hpp"
#include "security_options.hpp"

namespace cellmap::cli {
namespace {

using nlohmann::json;

// The boxes in the form of the boxes JSON file (docs/boxes-json.md), produced by its one serialiser.
json boxes_json(const std::vector<Box>& boxes) {
  return json::parse(to_json(BoxSet{0, "cell", boxes}))["boxes"];
}

json message_json(const transport::EnvironmentMessage& message) {
  if (const auto* env = std::get_if<Environment>(&message)) {
    return {{"type", "snapshot"},
            {"cell", env->cell()},
            {"version", env->version()},
            {"stamp_ns", env->stamp_ns()},
            {"boxes", boxes_json(env->boxes())}};
  }
  const auto& delta = std::get<EnvironmentDelta>(message);
  return {{"type", "delta"},
          {"cell", delta.cell},
          {"version", delta.to_version},
          {"from_version", delta.from_version},
          {"to_version", delta.to_version},
          {"stamp_ns", delta.stamp_ns},
          {"added", boxes_json(delta.added)},
          {"modified", boxes_json(delta.modified)},
          {"removed", delta.removed}};
}

struct EchoOptions {
  std::uint32_t domain = 0;
  std::string cell;
  std::uint64_t count = 0;
  double timeout = 0;
  SecurityOptions security;
};

void run_echo(const EchoOptions& options) {
  const dds::Participant participant(options.domain, options.security.setting());
  transport::EnvironmentMonitor monitor(
      participant, options.cell.empty() ? transport::default_cell(participant) : options.cell);
  using Clock = std::chrono::steady_clock;
  const bool forever = options.timeout <= 0;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(forever ? 0.0 : options.timeout));
  std::uint64_t printed = 0;
  std::uint64_t rejected = 0;
  while (options.count == 0 || printed < options.count) {
    const auto left = forever ? std::chrono::nanoseconds(std::chrono::seconds(1))
                              : std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - Clock::now());
    if (!forever && left.count() <= 0) {
      std::ostringstream reason;
      reason << "echo: timed out after " << options.timeout << " s with " << printed << " of "
             << options.count << " messages";
      throw Error(reason.str());
    }
    for (const transport::EnvironmentMessage& message :
         monitor.take(std::min(left, std::chrono::nanoseconds(1'000'000'000)))) {
      std::cout << message_json(message).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)
                << std::endl;  // one line per message, flushed for pipes
      if (++printed == options.count) break;
    }
    if (monitor.rejected() > rejected) {
      rejected = monitor.rejected();
      std::cerr << "cellmap: echo: skipped a malformed sample: " << monitor.last_rejection() << "\n";
    }
  }
}

}  // namespace

void add_echo_command(CLI::App& app) {
  auto options = std::make_shared<EchoOptions>();
  CLI::App* echo =
      app.add_subcommand("echo", "Print one JSON line per environment snapshot/delta received over DDS");
  echo->add_option("--domain", options->domain, "DDS domain id")->check(CLI::Range(0, 232));
  echo->add_option(
      "--cell", options->cell,
      "only this cell's partition (default: every cell; with --security, the credentials' cell)");
  echo->add_option("--count", options->count, "Exit after this many messages (0: never)");
  echo->add_option("--timeout", options->timeout,
                   "Fail after this many seconds without --count messages (0: never)")
      ->check(CLI::NonNegativeNumber);
  add_security_options(echo, options->security, security::Role::kPlanner);
  echo->callback([options] { run_echo(*options); });
}

}  // namespace cellmap::cli
