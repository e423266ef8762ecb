// SPDX-License-Identifier: Apache-2.0
// The `cellmap` tool's front door as a process: an unknown subcommand is an error whatever the flags, and
// `cellmap status` says so when no daemon answers.
#include <gtest/gtest.h>

#include <string>

#include "support/dds_domains.hpp"
#include "support/test_support.hpp"
#include "transport/loopback.hpp"

namespace cellmap {
namespace {

test::CommandRun cellmap(const std::string& args) {
  return test::run_command(std::string(CELLMAP_TOOL) + " " + args + " 2>&1");
}

TEST(CellmapCliTest, AnUnknownSubcommandIsAnErrorWhateverTheFlags) {
  for (const char* args : {"nosuch", "nosuch --help", "--help nosuch", "nosuch --version"}) {
    SCOPED_TRACE(args);
    const test::CommandRun run = cellmap(args);
    EXPECT_EQ(run.status, 2);
    EXPECT_EQ(run.output.rfind("cellmap: unknown subcommand 'nosuch' (the subcommands: segment, ", 0), 0u)
        << run.output;
    EXPECT_NE(run.output.find("status"), std::string::npos) << run.output;
    EXPECT_EQ(run.output.find('\n'), run.output.size() - 1) << run.output;  // one line
  }
}

TEST(CellmapCliTest, HelpOfTheToolAndOfASubcommandStillSucceeds) {
  const test::CommandRun main_help = cellmap("--help");
  EXPECT_EQ(main_help.status, 0) << main_help.output;
  EXPECT_NE(main_help.output.find("status"), std::string::npos) << main_help.output;
  EXPECT_EQ(cellmap("segment --help").status, 0);
  const test::CommandRun status_help = cellmap("status --help");
  EXPECT_EQ(status_help.status, 0);
  for (const char* flag : {"--domain", "--cell", "--wait", "--json", "--security", "--role"})
    EXPECT_NE(status_help.output.find(flag), std::string::npos) << flag;
  EXPECT_EQ(cellmap("--version").output, "cellmap 0.1.0\n");
}

TEST(CellmapCliTest, StatusWithNoDaemonOnTheDomainFailsWithOneLine) {
  test::use_loopback();
  const std::string domain = std::to_string(test::domain::kNobodyListening);
  const test::CommandRun run = cellmap("status --domain " + domain + " --wait 0.5");
  EXPECT_EQ(run.status, 1);
  EXPECT_EQ(run.output, "cellmap: status: no cellmapd answered on domain " + domain + " within 0.5 s\n");
  const test::CommandRun one_cell =
      cellmap("status --domain " + domain + " --cell press-3 --wait 0.5 --json");
  EXPECT_EQ(one_cell.status, 1);
  EXPECT_EQ(one_cell.output, "cellmap: status: no cellmapd of cell 'press-3' answered on domain " + domain +
                                 " within 0.5 s\n");
}

}  // namespace
}  // namespace cellmap
