// SPDX-License-Identifier: Apache-2.0
// The check every DDS program makes before joining with DDS Security: each way a credentials directory can be
// wrong is refused with one line naming the file and the reason.
#include "cellmap/security/credentials.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/security/cell_setup.hpp"
#include "cellmap/transport/topics.hpp"
#include "support/test_support.hpp"

namespace cellmap::security {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
constexpr std::uint32_t kDomain = 7;

class CredentialsTest : public ::testing::Test {
 protected:
  // A fresh set for cell-7 (and, for the wrong-CA cases, another one with CAs of its own).
  static void write(const fs::path& directory) {
    CellSetup setup;
    setup.directory = directory;
    setup.cell = "cell-7";
    setup.domain = kDomain;
    setup.valid_from = std::chrono::system_clock::now() - 1h;
    setup.valid_until = setup.valid_from + 24h * 30;
    setup.ca_valid_until = setup.valid_until;
    setup.grants = transport::role_grants(setup.cell);
    setup.ca = ca_of(directory);
    write_cell_credentials(setup);
  }
  static CaFolder ca_of(const fs::path& directory) { return {directory.string() + "-ca", "a passphrase"}; }
  void SetUp() override { write(cell_); }

  [[nodiscard]] std::string refusal(
      Role role = Role::kPlanner, std::uint32_t domain = kDomain,
      std::chrono::system_clock::time_point now = std::chrono::system_clock::now()) {
    const std::string message = test::error_of([&] { (void)check({cell_, role}, domain, now); });
    EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
    return message;
  }
  // Replaces `file` of this set by the same file of another set (other CAs).
  void take_from_other_set(const fs::path& relative) {
    if (!fs::exists(other_ / "identity_ca.pem")) write(other_);
    fs::copy_file(other_ / relative, cell_ / relative, fs::copy_options::overwrite_existing);
  }

  test::TempDir dir_;
  const fs::path cell_ = dir_.path() / "cell-7";
  const fs::path other_ = dir_.path() / "other";
  const RoleFiles planner_ = role_files(cell_, Role::kPlanner);
};

TEST_F(CredentialsTest, AGoodSetPasses) {
  EXPECT_EQ(refusal(), "");
  EXPECT_EQ(refusal(Role::kDaemon), "");
}

TEST_F(CredentialsTest, MissingOrUnreadableFilesAreNamed) {
  fs::remove(planner_.certificate);
  EXPECT_EQ(refusal(), planner_.certificate.string() + ": missing");
  fs::create_directory(planner_.certificate);
  EXPECT_EQ(refusal(), planner_.certificate.string() + ": not a regular file");
  EXPECT_EQ(test::error_of([&] {
              (void)check({dir_.path() / "nowhere", Role::kPlanner}, kDomain);
            }),
            (dir_.path() / "nowhere" / "identity_ca.pem").string() + ": missing");
}

TEST_F(CredentialsTest, FilesThatAreNotWhatTheyClaimAreRefused) {
  std::ofstream(planner_.certificate) << "hello\n";
  EXPECT_EQ(refusal(), planner_.certificate.string() + ": not a PEM certificate");
  std::ofstream(planner_.private_key, std::ios::trunc) << read_file(planner_.permissions);
  fs::copy_file(role_files(cell_, Role::kDaemon).certificate, planner_.certificate,
                fs::copy_options::overwrite_existing);
  EXPECT_EQ(refusal(), planner_.private_key.string() + ": not an unencrypted PEM private key");
}

TEST_F(CredentialsTest, ExpiredOrNotYetValidCredentialsAreRefused) {
  const std::string expired = refusal(Role::kPlanner, kDomain, std::chrono::system_clock::now() + 24h * 31);
  EXPECT_EQ(expired.rfind((cell_ / "identity_ca.pem").string() + ": expired on 20", 0), 0u) << expired;
  const std::string early = refusal(Role::kPlanner, kDomain, std::chrono::system_clock::now() - 2h);
  EXPECT_EQ(early.rfind((cell_ / "identity_ca.pem").string() + ": not valid before 20", 0), 0u) << early;
}

TEST_F(CredentialsTest, AnIdentityOfAnotherCaIsRefused) {
  take_from_other_set("planner/identity.pem");
  take_from_other_set("planner/identity_key.pem");
  EXPECT_EQ(refusal(), planner_.certificate.string() + ": not signed by the identity CA " +
                           (cell_ / "identity_ca.pem").string());
}

TEST_F(CredentialsTest, AKeyOthersCanReadOrOfAnotherIdentityIsRefused) {
  ASSERT_EQ(::chmod(planner_.private_key.c_str(), 0640), 0);
  EXPECT_EQ(refusal(),
            planner_.private_key.string() + ": group or others have access (mode 0640); chmod 600 it");
  ASSERT_EQ(::chmod(planner_.private_key.c_str(), 0604), 0);
  EXPECT_NE(refusal().find("(mode 0604)"), std::string::npos);
  fs::copy_file(role_files(cell_, Role::kDaemon).private_key, planner_.private_key,
                fs::copy_options::overwrite_existing);
  ASSERT_EQ(::chmod(planner_.private_key.c_str(), 0600), 0);
  EXPECT_EQ(refusal(), planner_.private_key.string() + ": not the key of " + planner_.certificate.string());
}

TEST_F(CredentialsTest, ADocumentOfAnotherPermissionsCaIsRefused) {
  take_from_other_set("governance.p7s");
  const std::string message = refusal();
  EXPECT_EQ(message.rfind(planner_.governance.string() + ": not signed by the permissions CA " +
                              (cell_ / "permissions_ca.pem").string(),
                          0),
            0u)
      << message;
}

TEST_F(CredentialsTest, ADocumentChangedAfterSigningIsRefused) {
  std::string text = read_file(planner_.permissions);
  const std::size_t deny = text.find("<default>DENY</default>");
  ASSERT_NE(deny, std::string::npos);
  text.replace(deny, 23, "<default>ALLOW</default>");  // granting oneself everything
  std::ofstream(planner_.permissions, std::ios::trunc) << text;
  const std::string message = refusal();
  EXPECT_EQ(message.rfind(planner_.permissions.string() + ": signature does not match the content", 0), 0u)
      << message;
}

TEST_F(CredentialsTest, DocumentsOfAnotherDomainOrRoleAreRefused) {
  EXPECT_EQ(refusal(Role::kPlanner, kDomain + 1),
            planner_.governance.string() + ": made for DDS domain 7, not 8");
  fs::copy_file(role_files(cell_, Role::kDaemon).permissions, planner_.permissions,
                fs::copy_options::overwrite_existing);
  EXPECT_EQ(refusal(),
            planner_.permissions.string() +
                ": made for CN=daemon,OU=cell-7,O=cellmap, not for CN=planner,OU=cell-7,O=cellmap");
}

TEST_F(CredentialsTest, ACaKeyInTheRuntimeFolderIsRefused) {
  // The layout of earlier versions: the CA keys in ca/ of the folder every host got a copy of.
  fs::create_directories(cell_ / "ca");
  fs::copy_file(ca_of(cell_).directory / "identity_ca_key.pem", cell_ / "ca" / "identity_ca_key.pem");
  EXPECT_EQ(refusal(), (cell_ / "ca" / "identity_ca_key.pem").string() +
                           ": a CA private key in the runtime folder: whoever reads this folder can issue "
                           "credentials for the cell; move it to the CA's own machine (docs/security.md, "
                           "\"Where keys live\")");
  fs::remove_all(cell_ / "ca");
  fs::copy_file(ca_of(cell_).directory / "permissions_ca_key.pem", cell_ / "permissions_ca_key.pem");
  EXPECT_EQ(refusal().rfind((cell_ / "permissions_ca_key.pem").string() + ": a CA private key", 0), 0u);
}

TEST_F(CredentialsTest, ARevokedIdentityIsRefusedAndTheOthersPass) {
  const std::string subject = revoke(planner_.certificate, ca_of(cell_), {cell_});
  EXPECT_EQ(subject, "CN=planner,OU=cell-7,O=cellmap");
  const std::string message = refusal();
  EXPECT_EQ(message.rfind(planner_.certificate.string() + ": revoked on 20", 0), 0u) << message;
  EXPECT_NE(message.find("(" + planner_.revocations.string() + ")"), std::string::npos) << message;
  EXPECT_NO_THROW((void)check({cell_, Role::kDaemon}, kDomain));
  // Revoking twice lists it once, and the list stays the CA's.
  (void)revoke(planner_.certificate, ca_of(cell_), {cell_});
  EXPECT_NO_THROW((void)check({cell_, Role::kTool}, kDomain));
}

TEST_F(CredentialsTest, ARevocationListOfAnotherCaIsRefused) {
  write(other_);
  (void)revoke(role_files(other_, Role::kTool).certificate, ca_of(other_), {other_});
  take_from_other_set("revoked.crl");
  EXPECT_EQ(refusal(), planner_.revocations.string() + ": not signed by the identity CA " +
                           planner_.identity_ca.string());
  std::ofstream(planner_.revocations) << "not a list";
  EXPECT_EQ(refusal(), planner_.revocations.string() + ": not a PEM certificate revocation list");
}

TEST(RoleTest, NamesRoundTripAndUnknownOnesAreRefused) {
  for (Role role : all_roles()) EXPECT_EQ(parse_role(to_string(role)), role);
  EXPECT_EQ(test::error_of([] { (void)parse_role("admin"); }),
            "role: 'admin' is not one of daemon, planner, robot, tool");
}

}  // namespace
}  // namespace cellmap::security
