// SPDX-License-Identifier: Apache-2.0
// `cellmap security init`'s library side: every file of a cell's credentials, with its mode, and documents
// that grant each role exactly its topics. The credential check (credentials_test.cpp) is the referee for
// signatures and validity.
#include "cellmap/security/cell_setup.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>

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
  setup.ca_valid_until = setup.valid_from + 24h * 365;
  setup.grants = transport::role_grants(setup.cell);
  setup.ca = {directory.string() + "-ca", "a passphrase"};
  return setup;
}

TEST(CellSetupTest, WritesEveryRoleWithPrivateKeysOnlyForTheOwner) {
  test::TempDir dir;
  const CellSetup setup = setup_in(dir.path() / "cell-7");
  const mode_t old_umask = ::umask(0);  // wide open: the modes must not depend on it
  write_cell_credentials(setup);
  ::umask(old_umask);
  EXPECT_EQ(mode_of(setup.directory), 0700u);
  EXPECT_EQ(mode_of(setup.ca.directory), 0700u);
  EXPECT_EQ(mode_of(setup.ca.directory / "identity_ca_key.pem"), 0600u);
  EXPECT_EQ(mode_of(setup.ca.directory / "permissions_ca_key.pem"), 0600u);
  // The CA keys are encrypted at rest and never in the runtime folder.
  EXPECT_NE(read_file(setup.ca.directory / "identity_ca_key.pem").find("BEGIN ENCRYPTED PRIVATE KEY"),
            std::string::npos);
  for (const auto& entry : fs::recursive_directory_iterator(setup.directory))
    EXPECT_EQ(entry.path().filename().string().find("_ca_key"), std::string::npos) << entry.path();
  EXPECT_EQ(read_file(setup.directory / "identity_ca.pem"),
            read_file(setup.ca.directory / "identity_ca.pem"));
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
    const std::string permissions =
        read_file(role_files(dir.path(), role).permissions.replace_extension(".xml"));
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

TEST(CellSetupTest, TheCaFolderIsNewOrEmptyOutsideTheRuntimeFolderWithAPassphrase) {
  test::TempDir dir;
  CellSetup setup = setup_in(dir.path() / "a");
  setup.ca.directory = setup.directory / "ca";
  EXPECT_EQ(test::error_of([&] { write_cell_credentials(setup); }),
            "--ca: " + setup.ca.directory.string() + ": the CA folder and the runtime folder " +
                setup.directory.string() + " must not hold one another (the CA keys never go to a host)");
  setup = setup_in(dir.path() / "a");
  setup.ca.passphrase = "short";
  EXPECT_EQ(test::error_of([&] { write_cell_credentials(setup); }), "CA passphrase: shorter than 8 bytes");
  setup = setup_in(dir.path() / "a");
  setup.ca_valid_until = setup.valid_until - 1h;
  EXPECT_EQ(test::error_of([&] { write_cell_credentials(setup); }),
            "--ca-days: the CAs must stay valid at least as long as the credentials they issue (--days)");
  EXPECT_FALSE(fs::exists(setup.directory)) << "refused before writing anything";
}

TEST(CellSetupTest, ACellOfAPlantIsIssuedWithAnotherCellsCas) {
  test::TempDir dir;
  const CellSetup first = setup_in(dir.path() / "cell-7");
  write_cell_credentials(first);
  CellSetup second = setup_in(dir.path() / "cell-8");
  second.cell = "cell-8";
  second.grants = transport::role_grants(second.cell);
  second.ca = first.ca;
  second.existing_ca = true;
  write_cell_credentials(second);
  EXPECT_FALSE(fs::exists(dir.path() / "cell-8-ca")) << "new CAs were made";
  EXPECT_EQ(read_file(second.directory / "identity_ca.pem"), read_file(first.directory / "identity_ca.pem"));
  EXPECT_EQ(read_file(second.directory / "permissions_ca.pem"),
            read_file(first.directory / "permissions_ca.pem"));
  for (Role role : all_roles()) {
    const Credentials credentials = check({second.directory, role}, 7);
    EXPECT_EQ(credentials.cell, "cell-8");
    EXPECT_NE(read_file(role_files(second.directory, role).permissions).find("cellmap/cell-8"),
              std::string::npos);
  }

  CellSetup wrong_passphrase = setup_in(dir.path() / "cell-9");
  wrong_passphrase.ca = {first.ca.directory, "not the passphrase"};
  wrong_passphrase.existing_ca = true;
  EXPECT_EQ(test::error_of([&] { write_cell_credentials(wrong_passphrase); }),
            (first.ca.directory / "identity_ca_key.pem").string() + ": wrong CA passphrase");
  CellSetup orphan = setup_in(dir.path() / "cell-10");
  orphan.ca.directory = second.directory;  // a runtime folder holds no CA keys
  orphan.existing_ca = true;
  EXPECT_EQ(test::error_of([&] {
              write_cell_credentials(orphan);
            }).rfind((second.directory / "identity_ca_key.pem").string(), 0),
            0u);
}

TEST(CellSetupTest, NoCredentialsOutliveThePlantsCas) {
  test::TempDir dir;
  const CellSetup first = setup_in(dir.path() / "cell-7");  // CAs valid for a year
  write_cell_credentials(first);
  CellSetup second = setup_in(dir.path() / "cell-8");
  second.ca = first.ca;
  second.existing_ca = true;
  second.valid_until = second.valid_from + 24h * 3650;
  const std::string refusal = test::error_of([&] { write_cell_credentials(second); });
  EXPECT_EQ(refusal.rfind("--days: the credentials would stay valid until ", 0), 0u) << refusal;
  EXPECT_NE(refusal.find((first.ca.directory / "identity_ca.pem").string() + " expires (" +
                         utc_text(first.ca_valid_until) + "): give fewer days, or new CAs"),
            std::string::npos)
      << refusal;
}

TEST(CellSetupTest, AnExportHoldsOneRolesFilesAndNoOtherKey) {
  test::TempDir dir;
  const CellSetup setup = setup_in(dir.path() / "cell-7");
  write_cell_credentials(setup);
  const fs::path out = dir.path() / "for-planner-host";
  export_role(setup.directory, Role::kPlanner, out);
  EXPECT_EQ(mode_of(out), 0700u);
  EXPECT_EQ(mode_of(out / "planner" / "identity_key.pem"), 0600u);
  std::vector<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(out))
    if (entry.is_regular_file()) files.push_back(entry.path().lexically_relative(out).string());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string>{"governance.p7s", "identity_ca.pem", "permissions_ca.pem",
                                             "planner/identity.pem", "planner/identity_key.pem",
                                             "planner/permissions.p7s"}));
  const Credentials credentials = check({out, Role::kPlanner}, 7);
  EXPECT_EQ(credentials.subject, "CN=planner,OU=cell-7,O=cellmap");
  EXPECT_NE(test::error_of([&] { (void)check({out, Role::kDaemon}, 7); }), "");
  EXPECT_EQ(
      test::error_of([&] { export_role(setup.directory, Role::kPlanner, out); }),
      out.string() + ": not empty; credentials are never overwritten (write a new set into a new directory)");
}

TEST(CellSetupTest, AHostsOwnIdentityIsRevokedAloneAndTheListTravelsWithExports) {
  test::TempDir dir;
  const CellSetup setup = setup_in(dir.path() / "cell-7");
  write_cell_credentials(setup);
  HostIdentity request;
  request.directory = setup.directory;
  request.role = Role::kPlanner;
  request.grants = setup.grants.at(Role::kPlanner);
  request.valid_from = setup.valid_from;
  request.valid_until = setup.valid_until;
  request.ca = setup.ca;
  request.host = "planner-2";
  request.out = dir.path() / "planner-2";
  issue_host_identity(request);
  request.host = "planner-3";
  request.out = dir.path() / "planner-3";
  issue_host_identity(request);
  EXPECT_EQ(check({dir.path() / "planner-2", Role::kPlanner}, 7).subject,
            "CN=planner@planner-2,OU=cell-7,O=cellmap");
  EXPECT_NE(read_file(dir.path() / "planner-2" / "planner" / "permissions.p7s")
                .find("<subject_name>CN=planner@planner-2,OU=cell-7,O=cellmap</subject_name>"),
            std::string::npos);

  EXPECT_EQ(revoke(dir.path() / "planner-2" / "planner" / "identity.pem", setup.ca, {setup.directory}),
            "CN=planner@planner-2,OU=cell-7,O=cellmap");
  EXPECT_TRUE(fs::exists(setup.ca.directory / "revoked.crl"));
  EXPECT_EQ(read_file(setup.directory / "revoked.crl"), read_file(setup.ca.directory / "revoked.crl"));
  // The cell's own planner identity and planner-3 stay valid; an export now carries the list.
  EXPECT_NO_THROW((void)check({setup.directory, Role::kPlanner}, 7));
  export_role(setup.directory, Role::kPlanner, dir.path() / "planner-1");
  EXPECT_EQ(read_file(dir.path() / "planner-1" / "revoked.crl"), read_file(setup.directory / "revoked.crl"));
  fs::copy_file(setup.directory / "revoked.crl", dir.path() / "planner-2" / "revoked.crl");
  EXPECT_EQ(test::error_of([&] {
              (void)check({dir.path() / "planner-2", Role::kPlanner}, 7);
            }).rfind((dir.path() / "planner-2" / "planner" / "identity.pem").string() + ": revoked on ", 0),
            0u);

  request.host = "bad,host";
  request.out = dir.path() / "bad";
  EXPECT_EQ(test::error_of([&] { issue_host_identity(request); }),
            "--host: 'bad,host': use 1-64 of A-Z a-z 0-9 . _ -");
  CellSetup other = setup_in(dir.path() / "other");
  write_cell_credentials(other);
  EXPECT_EQ(test::error_of([&] { (void)revoke(other.directory / "tool" / "identity.pem", setup.ca, {}); }),
            (other.directory / "tool" / "identity.pem").string() + ": not issued by the identity CA of " +
                setup.ca.directory.string());
}

}  // namespace
}  // namespace cellmap::security
