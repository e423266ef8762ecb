// SPDX-License-Identifier: Apache-2.0
// `cellmap status` against cellmapd on the simulated cell with two sensors, on loopback DDS: the table and
// the JSON show the cell, its state, its sensors by name and the version the daemon has.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "daemon/service_e2e.hpp"
#include "support/dds_domains.hpp"

namespace cellmap {
namespace {

constexpr const char* kCell = "status-e2e";

test::CommandRun cellmap(const std::string& args) {
  return test::run_command(std::string(CELLMAP_TOOL) + " " + args);
}

TEST(StatusCommandE2eTest, ShowsTheDaemonsStateVersionAndSensors) {
  test::use_loopback();
  const int domain = test::domain::kStatusCommand;
  const test::TempDir dir;
  const std::filesystem::path config = dir.path() / "cellmapd.yaml";
  std::ofstream(config)
      << "cell: " << kCell
      << "\nsweep_period: 0.2\nstatus_period: 0.5\n"
         "sources: [{sensor: kinect, noise: false}, {sensor: realsense, noise: false}]\n"
         // The first version after 3 sweeps, not 15: the test is about the report, not the map.
         "change: {settle_sweeps: 3}\n";
  test::ChildProcess daemon({CELLMAPD, "--config", config.string(), "--domain", std::to_string(domain),
                             "--state-dir", (dir.path() / "state").string()});
  const dds::Participant observer(static_cast<std::uint32_t>(domain));
  transport::StatusReader reader(observer, kCell);
  const std::optional<transport::CellStatus> first =
      test::wait_for_status(reader, kCell, [](const transport::CellStatus& s) { return s.version >= 1; });
  ASSERT_TRUE(first) << "no version from cellmapd";

  const std::string flags = "--domain " + std::to_string(domain);
  const test::CommandRun json_run = cellmap("status " + flags + " --cell " + kCell + " --json");
  ASSERT_EQ(json_run.status, 0) << json_run.output;
  const nlohmann::json document = nlohmann::json::parse(json_run.output);
  EXPECT_EQ(document.at("domain"), domain);
  ASSERT_EQ(document.at("cells").size(), 1u) << document;
  const nlohmann::json& cell = document["cells"][0];
  EXPECT_EQ(cell.at("cell"), kCell);
  EXPECT_EQ(cell.at("state"), "running");
  EXPECT_EQ(cell.at("sensors"), nlohmann::json::parse(R"([{"name":"kinect","state":"streaming"},
                                                          {"name":"realsense","state":"streaming"}])"));
  EXPECT_EQ(cell.at("dropped_frames"), 0);
  EXPECT_EQ(cell.at("refused_inputs"), 0);
  // The version it printed is the daemon's at that time: between the one seen before and the one after.
  const auto version = cell.at("version").get<std::uint64_t>();
  const auto sweeps = cell.at("sweeps").get<std::uint64_t>();
  EXPECT_GE(version, first->version);
  const std::optional<transport::CellStatus> later =
      test::wait_for_status(reader, kCell, [&](const transport::CellStatus& s) { return s.sweeps > sweeps; });
  ASSERT_TRUE(later);
  EXPECT_LE(version, later->version);

  // Every cell on the domain, as a table: the cell's row, then its sensors.
  const test::CommandRun table = cellmap("status " + flags + " --wait 1");
  ASSERT_EQ(table.status, 0) << table.output;
  EXPECT_EQ(table.output.rfind("CELL        STATE    VERSION  BOXES  SWEEPS  DROPPED  REFUSED  LAST SWEEP\n"
                               "status-e2e  running  ",
                               0),
            0u)
      << table.output;
  EXPECT_NE(table.output.find("status-e2e  kinect     streaming\nstatus-e2e  realsense  streaming\n"),
            std::string::npos)
      << table.output;
}

}  // namespace
}  // namespace cellmap
