// SPDX-License-Identifier: Apache-2.0
// `cellmap security init`'s library side: every file of a cell's credentials, with its mode, and documents
// that grant each role exactly its topics. The credential check (credentials_test.cpp) is the referee for
// signatures and validity.
#include "cellmap/security/cell_setup.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/transport/topics.hpp"
#include "support/test_support.hpp"

namespace cellmap::security {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

unsigned mode_of(const fs::path& path) {
  struct stat info {};
  EXPECT_EQ(::stat(path.c_str(), &info), 0) << path;
  return info.st_mode & 07777;
}

CellSetup setup_in(const fs::path& directory) {
  CellSetup setup;
  setup.directory = directory;
  setup.cell = "cell-7";
  setup.domain = 7;
  // Whole seconds: certificates keep no fractions.
  setup.valid_from = std::chrono::system_clock::from_time_t(
      std::chrono::system_clock::to_time_t(std::chrono::system_clock::now() - 1h));
  setup.valid_until = setup.valid_from + 24h * 30;
  setup.grants = transport::role_grants(setup.cell);
  return setup;
}

TEST(CellSetupTest, WritesEveryRoleWithPrivateKeysOnlyForTheOwner) {
  test::TempDir dir;
  const CellSetup setup = setup_in(dir.path() / "cell-7");
  write_cell_credentials(setup);
  EXPECT_EQ(mode_of(setup.directory / "ca"), 0700u);
  EXPECT_EQ(mode_of(setup.directory / "ca" / "identity_ca_key.pem"), 0600u);
  EXPECT_EQ(mode_of(setup.directory / "ca" / "permissions_ca_key.pem"), 0600u);
  EXPECT_EQ(mode_of(setup.directory / "identity_ca.pem"), 0644u);
  EXPECT_EQ(mode_of(setup.directory / "governance.p7s"), 0644u);
  for (Role role : all_roles()) {
    const RoleFiles files = role_files(setup.directory, role);
    EXPECT_EQ(mode_of(files.certificate.parent_path()), 0700u) << to_string(role);
    EXPECT_EQ(mode_of(files.private_key), 0600u) << to_string(role);
    EXPECT_EQ(mode_of(files.certificate), 0644u) << to_string(role);
    EXPECT_EQ(mode_of(files.permissions), 0644u) << to_string(role);
    // What a participant checks before joining: signatures, validity, domain, subject.
    const Credentials credentials = check({setup.directory, role}, 7);
    EXPECT_EQ(credentials.subject, std::string("CN=") + to_string(role) + ",OU=cell-7,O=cellmap");
    EXPECT_EQ(credentials.expires, setup.valid_until);
  }
}

TEST(CellSetupTest, DocumentsGrantEachRoleItsTopicsOnly) {
  test::TempDir dir;
  const CellSetup setup = setup_in(dir.path());
  write_cell_credentials(setup);
  const std::string governance = read_file(dir.path() / "governance.xml");
  for (const char* topic : {"cellmap/environment", "cellmap/environment_delta", "cellmap/status",
                            "cellmap/sim/scene_edits", "cellmap/robot_state", "cellmap/robot_joints"}) {
    EXPECT_NE(governance.find(std::string("<topic_expression>") + topic + "</topic_expression>"),
              std::string::npos)
        << topic;
  }
  EXPECT_NE(governance.find("<allow_unauthenticated_participants>false"), std::string::npos);
  EXPECT_NE(governance.find("<data_protection_kind>ENCRYPT"), std::string::npos);
  EXPECT_NE(governance.find("<domains>\n        <id>7</id>"), std::string::npos);

  const std::string planner = read_file(dir.path() / "planner" / "permissions.xml");
  EXPECT_EQ(planner.find("<publish>"), std::string::npos) << "the planner must write nothing";
  EXPECT_NE(planner.find("<topic>cellmap/environment_delta</topic>"), std::string::npos);
  const std::string robot = read_file(dir.path() / "robot" / "permissions.xml");
  EXPECT_EQ(robot.find("<subscribe>"), std::string::npos);
  EXPECT_NE(robot.find("<topic>cellmap/robot_joints</topic>"), std::string::npos);
  EXPECT_EQ(robot.find("cellmap/environment"), std::string::npos);
  // Every grant in the cell's partition only.
  for (Role role : all_roles()) {
    const std::string permissions = read_file(role_files(dir.path(), role).permissions.replace_extension(".xml"));
    EXPECT_NE(permissions.find("<partitions>\n            <partition>cellmap/cell-7</partition>\n"),
              std::string::npos)
        << to_string(role);
    EXPECT_EQ(permissions.find("cellmap/*"), std::string::npos) << to_string(role);
  }
  const std::string daemon = read_file(dir.path() / "daemon" / "permissions.xml");
  EXPECT_NE(daemon.find("<subject_name>CN=daemon,OU=cell-7,O=cellmap</subject_name>"), std::string::npos);
  EXPECT_NE(daemon.find("<default>DENY</default>"), std::string::npos);
}

TEST(CellSetupTest, RefusesBadOptionsAndNeverOverwrites) {
  test::TempDir dir;
  CellSetup setup = setup_in(dir.path() / "a");
  setup.cell = "cell,OU=admin";
  EXPECT_EQ(test::error_of([&] { write_cell_credentials(setup); }),
            "--cell: 'cell,OU=admin': use 1-64 of A-Z a-z 0-9 . _ -");
  setup = setup_in(dir.path() / "a");
  setup.domain = 233;
  EXPECT_EQ(test::error_of([&] { write_cell_credentials(setup); }), "--domain: 233 is not in 0-232");
  setup = setup_in(dir.path() / "a");
  setup.valid_until = setup.valid_from;
  EXPECT_NE(test::error_of([&] { write_cell_credentials(setup); }), "");
  setup = setup_in(dir.path() / "a");
  write_cell_credentials(setup);
  EXPECT_EQ(test::error_of([&] { write_cell_credentials(setup); }),
            (dir.path() / "a").string() +
                ": not empty; credentials are never overwritten (write a new set into a new directory)");
}

TEST(CellSetupTest, ACellOfAPlantIsIssuedWithAnotherCellsCas) {
  test::TempDir dir;
  const CellSetup first = setup_in(dir.path() / "cell-7");
  write_cell_credentials(first);
  CellSetup second = setup_in(dir.path() / "cell-8");
  second.cell = "cell-8";
  second.grants = transport::role_grants(second.cell);
  second.plant_ca = first.directory;
  write_cell_credentials(second);
  EXPECT_FALSE(fs::exists(second.directory / "ca")) << "the plant's CA keys were copied";
  EXPECT_EQ(read_file(second.directory / "identity_ca.pem"), read_file(first.directory / "identity_ca.pem"));
  EXPECT_EQ(read_file(second.directory / "permissions_ca.pem"),
            read_file(first.directory / "permissions_ca.pem"));
  for (Role role : all_roles()) {
    const Credentials credentials = check({second.directory, role}, 7);
    EXPECT_EQ(credentials.cell, "cell-8");
    EXPECT_NE(read_file(role_files(second.directory, role).permissions).find("cellmap/cell-8"), std::string::npos);
  }

  CellSetup orphan = setup_in(dir.path() / "cell-9");
  orphan.plant_ca = second.directory;  // holds no CA keys
  EXPECT_EQ(test::error_of([&] { write_cell_credentials(orphan); }).rfind((second.directory / "ca").string(), 0),
            0u);
}

}  // namespace
}  // namespace cellmap::security
