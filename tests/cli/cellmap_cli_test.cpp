// SPDX-License-Identifier: Apache-2.0
// The `cellmap` tool's front door as a process: an unknown subcommand is an error whatever the flags,
// `cellmap status` says so when no daemon answers, and `cellmap security` issues, exports and revokes as an
// operator runs it (the CA passphrase from a file, never on the command line).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
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

TEST(CellmapCliTest, SecurityKeepsTheCaApartAndExportsIssuesAndRevokesFromIt) {
  test::TempDir dir;
  const std::string keys = (dir.path() / "keys" / "cell-1").string();
  const std::string passphrase = (dir.path() / "passphrase").string();
  std::ofstream(passphrase) << "correct horse battery\n";
  const test::CommandRun init =
      cellmap("security init " + keys + " --cell cell-1 --domain 9 --ca-passphrase-file " + passphrase);
  ASSERT_EQ(init.status, 0) << init.output;
  EXPECT_NE(
      init.output.find("issued by the CAs in " + keys + "-ca (new; keys encrypted with the passphrase)"),
      std::string::npos)
      << init.output;
  EXPECT_TRUE(std::filesystem::exists(keys + "-ca/identity_ca_key.pem"));
  EXPECT_FALSE(std::filesystem::exists(keys + "/ca"));

  const std::string host = (dir.path() / "planner-7").string();
  const test::CommandRun issue = cellmap("security issue " + keys + " --role planner --host planner-7 -o " +
                                         host + " --ca " + keys + "-ca --ca-passphrase-file " + passphrase);
  ASSERT_EQ(issue.status, 0) << issue.output;
  EXPECT_EQ(cellmap("security export " + keys + " --role robot -o " + (dir.path() / "robot").string()).status,
            0);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "robot" / "robot" / "identity_key.pem"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "robot" / "daemon"));

  const test::CommandRun revoke = cellmap("security revoke " + host + "/planner/identity.pem --ca " + keys +
                                          "-ca --into " + keys + " --ca-passphrase-file " + passphrase);
  ASSERT_EQ(revoke.status, 0) << revoke.output;
  EXPECT_EQ(revoke.output.rfind("revoked CN=planner@planner-7,OU=cell-1,O=cellmap in " + keys +
                                    "-ca/revoked.crl, "
                                    "copied into " +
                                    keys + "\n",
                                0),
            0u)
      << revoke.output;

  // Refused with one line each: no passphrase where none can be asked, a wrong one, too many days.
  const test::CommandRun no_passphrase =
      cellmap("security init " + (dir.path() / "b").string() + " --cell b < /dev/null");
  EXPECT_EQ(no_passphrase.status, 1);
  EXPECT_EQ(no_passphrase.output,
            "cellmap: the CA keys are encrypted: give --ca-passphrase-file FILE, or run on a terminal to be "
            "asked\n");
  std::ofstream(dir.path() / "wrong") << "not the passphrase\n";
  const test::CommandRun wrong =
      cellmap("security init " + (dir.path() / "c").string() + " --cell c --plant-ca " + keys +
              "-ca --ca-passphrase-file " + (dir.path() / "wrong").string());
  EXPECT_EQ(wrong.status, 1);
  EXPECT_EQ(wrong.output, "cellmap: " + keys + "-ca/identity_ca_key.pem: wrong CA passphrase\n");
  EXPECT_EQ(cellmap("security init " + (dir.path() / "d").string() + " --cell d --days 3651").status, 2);
}

}  // namespace
}  // namespace cellmap
