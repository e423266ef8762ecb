// SPDX-License-Identifier: Apache-2.0
// `cellmap status [--domain N] [--cell C] [--wait S] [--json] [--security DIR [--role R]]`: the daemons'
// reports on cellmap/status, as a table or one JSON document.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cellmap/common/error.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "cellmap/transport/status_reader.hpp"
#include "cellmap/transport/topics.hpp"
#include "cellmap/view/view_state.hpp"
#include "commands.hpp"
#include "security_options.hpp"

namespace cellmap::cli {
namespace {

using Clock = std::chrono::steady_clock;

struct StatusOptions {
  std::uint32_t domain = 0;
  std::string cell;
  double wait = 3.0;
  bool json = false;
  SecurityOptions security;
};

std::string seconds_text(double seconds) {
  std::ostringstream text;
  text << seconds;
  return text.str();
}

// Each cell's latest report within the wait. The topic is transient local, so a running daemon's last report
// arrives as soon as the reader matches it: with --cell the wait ends there; without, every cell that
// reports within the wait is listed.
std::map<std::string, transport::CellStatus> latest_reports(const StatusOptions& options) {
  const dds::Participant participant(options.domain, options.security.setting());
  transport::StatusReader reader(participant,
                                 options.cell.empty() ? transport::default_cell(participant) : options.cell);
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.wait));
  std::map<std::string, transport::CellStatus> latest;
  while (Clock::now() < deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - Clock::now());
    for (transport::CellStatus& status :
         reader.take(std::min<std::chrono::nanoseconds>(left, std::chrono::milliseconds(100))))
      latest[status.cell] = std::move(status);
    if (!options.cell.empty() && latest.count(options.cell) > 0) break;
  }
  return latest;
}

std::string last_sweep_text(std::int64_t last_sweep_ns) {
  if (last_sweep_ns == 0) return "never";
  const double ago = static_cast<double>(wall_clock_ns() - last_sweep_ns) * 1e-9;
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s ago", std::max(ago, 0.0));
  return text;
}

// Columns padded to their widest cell, two spaces apart.
void print_table(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> widths;
  for (const auto& row : rows) {
    widths.resize(std::max(widths.size(), row.size()));
    for (std::size_t i = 0; i < row.size(); ++i) widths[i] = std::max(widths[i], row[i].size());
  }
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t i = 0; i < row.size(); ++i)
      line += row[i] + (i + 1 < row.size() ? std::string(widths[i] - row[i].size() + 2, ' ') : "");
    std::cout << line << "\n";
  }
}

// A table of the cells, then a table of their sensors; a degraded cell's reason on a line of its own.
void print_human(const std::map<std::string, transport::CellStatus>& reports) {
  std::vector<std::vector<std::string>> cells{
      {"CELL", "STATE", "VERSION", "BOXES", "SWEEPS", "DROPPED", "REFUSED", "LAST SWEEP"}};
  std::vector<std::vector<std::string>> sensors{{"CELL", "SENSOR", "STATE"}};
  for (const auto& [cell, s] : reports) {
    cells.push_back({cell, s.state, std::to_string(s.version), std::to_string(s.boxes),
                     std::to_string(s.sweeps), std::to_string(s.dropped_frames),
                     std::to_string(s.refused_inputs), last_sweep_text(s.last_sweep_ns)});
    for (const transport::SensorStatus& sensor : s.sensors)
      sensors.push_back({cell, sensor.name, sensor.state});
  }
  print_table(cells);
  for (const auto& [cell, s] : reports) {
    if (!s.reason.empty()) std::cout << cell << ": " << s.state << ": " << s.reason << "\n";
  }
  std::cout << "\n";
  print_table(sensors);
}

void print_json(const std::map<std::string, transport::CellStatus>& reports, std::uint32_t domain) {
  nlohmann::json cells = nlohmann::json::array();
  for (const auto& entry : reports) cells.push_back(nlohmann::json::parse(view::status_json(entry.second)));
  std::cout << nlohmann::json({{"domain", domain}, {"cells", cells}})
                   .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)
            << "\n";
}

void run_status(const StatusOptions& options) {
  const std::map<std::string, transport::CellStatus> reports = latest_reports(options);
  if (reports.empty()) {
    const std::string whose = options.cell.empty() ? "cellmapd" : "cellmapd of cell '" + options.cell + "'";
    throw Error("status: no " + whose + " answered on domain " + std::to_string(options.domain) + " within " +
                seconds_text(options.wait) + " s");
  }
  if (options.json) {
    print_json(reports, options.domain);
  } else {
    print_human(reports);
  }
}

}  // namespace

void add_status_command(CLI::App& app) {
  auto options = std::make_shared<StatusOptions>();
  CLI::App* status = app.add_subcommand(
      "status",
      "Print the state, version, sensors, sweeps, dropped frames and refused inputs of the cellmapd "
      "daemons on a domain (cellmap/status)");
  status->add_option("--domain", options->domain, "DDS domain id")->check(CLI::Range(0, 232));
  status->add_option("--cell", options->cell,
                     "only this cell, and stop waiting once it reported (default: every cell that reports "
                     "within --wait; with --security, the credentials' cell)");
  status->add_option("--wait", options->wait, "seconds to wait for reports")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  status->add_flag("--json", options->json,
                   "one JSON document {\"domain\", \"cells\": [...]}, a cell's fields as on cellmap/status");
  add_security_options(status, options->security, security::Role::kPlanner);
  status->callback([options] { run_status(*options); });
}

}  // namespace cellmap::cli
