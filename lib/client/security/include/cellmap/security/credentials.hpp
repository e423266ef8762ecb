// SPDX-License-Identifier: Apache-2.0
#pragma once
// DDS Security credentials of one cell, as `cellmap security init DIR` writes them (cell_setup.hpp), and the
// check a program makes before it hands them to DDS:
//
//   DIR/identity_ca.pem          the identity CA's certificate: who may join
//   DIR/permissions_ca.pem       the permissions CA's certificate: who signs the documents below
//   DIR/governance.p7s           the domain's rules (S/MIME, signed by the permissions CA)
//   DIR/<role>/identity.pem      the role's certificate, signed by the identity CA
//   DIR/<role>/identity_key.pem  its private key (mode 0600: refused when group or others have access)
//   DIR/<role>/permissions.p7s   what the role may write and read (S/MIME, signed by the permissions CA)
//   DIR/revoked.crl              the identities revoked (signed by the identity CA); only after a revoke
//
// A participant needs only its role's files and the shared ones (`cellmap security export` copies exactly
// those). The CAs' private keys live in a CA folder elsewhere (cell_setup.hpp); a runtime folder that holds
// one is refused.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace cellmap::security {

/// What a participant may do on the cell's topics (the grants are in transport/topics.hpp).
enum class Role { kDaemon, kPlanner, kRobot, kTool };

/// "daemon", "planner", "robot", "tool": the names used in flags, config, directories and logs.
[[nodiscard]] const char* to_string(Role role);
/// @throws Error "role: 'NAME' is not one of daemon, planner, robot, tool".
[[nodiscard]] Role parse_role(const std::string& name);
/// Every role, in the order above.
[[nodiscard]] const std::vector<Role>& all_roles();

/// Where one role's files are in a credentials directory.
struct RoleFiles final {
  std::filesystem::path identity_ca;
  std::filesystem::path permissions_ca;
  std::filesystem::path governance;
  std::filesystem::path certificate;
  std::filesystem::path private_key;
  std::filesystem::path permissions;
  std::filesystem::path revocations;  ///< may not exist: nothing revoked yet
};
[[nodiscard]] RoleFiles role_files(const std::filesystem::path& directory, Role role);

/// `--security DIR --role R`: turns DDS Security on for one participant.
struct Setting final {
  std::filesystem::path directory;
  Role role = Role::kPlanner;
};

/// A role's files after check(): absolute paths, and what they say.
struct Credentials final {
  RoleFiles files;
  std::string subject;  ///< the certificate's subject, e.g. "CN=planner,OU=cell-1,O=cellmap"
  std::string cell;  ///< the cell they are for (the subject's OU): their permissions grant its partition only
  /// The earliest end of validity among the certificates and the permissions: after it the participant
  /// can no longer join (and a running one loses its peers).
  std::chrono::system_clock::time_point expires;
};

/// Checks a role's files before they go to DDS, so that a bad set is refused at start with one line instead
/// of DDS's generic failure. Each file must exist and be readable and be what it claims (PEM certificate,
/// unencrypted PEM private key, S/MIME document); the private key must give group and others no access and
/// belong to the certificate; the certificates must be within their validity at `now`, the role's signed by
/// the identity CA; the documents must be signed by the permissions CA, made for `domain`, and the
/// permissions for this certificate's subject and within their validity. The subject must name a cell (OU).
/// A revocation list, if present, must be the identity CA's and must not list this certificate. The folder
/// must hold no CA private key (the old layout's `ca/` included): whoever reads it could issue credentials.
/// @throws Error "<file>: <reason>" naming the first file found wrong.
[[nodiscard]] Credentials check(const Setting& setting, std::uint32_t domain,
                                std::chrono::system_clock::time_point now = std::chrono::system_clock::now());

/// "2026-03-01T12:00:00Z": how times appear in messages and documents (UTC).
[[nodiscard]] std::string utc_text(std::chrono::system_clock::time_point time);

}  // namespace cellmap::security
