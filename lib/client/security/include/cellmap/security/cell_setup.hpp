// SPDX-License-Identifier: Apache-2.0
#pragma once
// `cellmap security init|export|issue|revoke`: everything one cell needs for DDS Security, made with OpenSSL
// (the runtime folder's layout is in credentials.hpp). Two CAs (identity, permissions; ECDSA P-256, SHA-256)
// in a folder of their own, one identity per role (and per host, if asked), the governance document and one
// permissions document per identity, both S/MIME-signed by the permissions CA as the DDS Security
// specification (1.1, 9.4.1.2–3) requires, and the identity CA's revocation list.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "cellmap/security/credentials.hpp"

namespace cellmap::security {

/// What one role may write (publish) and read (subscribe): DDS topic names, in the DDS partitions listed
/// (none: the default partition only). Everything else is denied: another partition, a partition pattern
/// that is not listed as such, a topic not listed.
struct TopicGrants final {
  std::vector<std::string> publish;
  std::vector<std::string> subscribe;
  std::vector<std::string> partitions;
};

/// How samples on the cell's topics travel. Either way only authenticated participants with the right
/// permissions match, and a tampered or replayed sample is dropped; kEncrypt (AES-GCM) also hides the
/// content from whoever captures the traffic, kSign (AES-GMAC) leaves it readable.
enum class DataProtection { kSign, kEncrypt };

/// The certificate authorities that issue a cell's credentials (or a whole plant's), kept apart from every
/// runtime folder: a host that runs a participant never needs them.
///   CA/identity_ca.pem, CA/permissions_ca.pem          their certificates
///   CA/identity_ca_key.pem, CA/permissions_ca_key.pem  their private keys, PKCS#8 encrypted with the
///                                                      passphrase (AES-256-CBC, PBKDF2), mode 0600
///   CA/revoked.crl                                     the identities revoked so far (after the first
///   revoke)
/// The folder is 0700.
struct CaFolder final {
  std::filesystem::path directory;
  /// Encrypts new keys (at least kMinPassphraseLength bytes) and decrypts existing ones.
  std::string passphrase;
};
inline constexpr std::size_t kMinPassphraseLength = 8;

struct CellSetup final {
  std::filesystem::path directory;  ///< the runtime folder: created (parents too); must not exist or be empty
  std::string cell;                 ///< 1-64 characters of [A-Za-z0-9._-]: it goes into certificate subjects
  std::uint32_t domain = 0;         ///< the only DDS domain the documents allow, 0-232
  std::chrono::system_clock::time_point valid_from;   ///< certificates and permissions, both
  std::chrono::system_clock::time_point valid_until;  ///< after valid_from, never after the CAs' own end
  std::map<Role, TopicGrants> grants;                 ///< every role's; the governance covers their topics
  DataProtection data_protection = DataProtection::kEncrypt;
  CaFolder ca;
  /// false: new CAs for this cell alone (its participants talk to no other cell's), written into
  /// `ca.directory` (new or empty, outside `directory`), valid until `ca_valid_until`. true: `ca.directory`
  /// holds a plant's CAs (as an earlier setup wrote them): they issue this cell, so the plant's participants
  /// authenticate each other, while each cell's permissions still grant only its own partitions.
  bool existing_ca = false;
  std::chrono::system_clock::time_point ca_valid_until;  ///< new CAs only; not before valid_until
};

/// Writes the credentials of `setup.cell` into `setup.directory` (the layout of credentials.hpp): private
/// keys with mode 0600 (created so, never wider for an instant), the role folders 0700, the rest 0644; new
/// CAs into `setup.ca`. The CAs' certificates (and revocation list) are copied into the runtime folder; their
/// keys never are. The plain XML of each signed document is written beside it (`.xml`) for reading; DDS
/// reads only the signed one.
/// @throws Error naming the option or path: bad cell id, domain, validity (also one beyond the CAs' own) or
/// passphrase, a role without grants, a folder that is not empty, a CA folder inside the runtime folder, an
/// existing CA folder without its certificates and keys (or a key that is not its certificate's, or a wrong
/// passphrase), a write or OpenSSL failure (the folder may then hold part of the set).
void write_cell_credentials(const CellSetup& setup);

/// The cell and DDS domain a runtime folder's credentials are for (its daemon's certificate and its
/// governance; nothing is verified here: check() does that before joining).
struct CellOfFolder final {
  std::string cell;
  std::uint32_t domain = 0;
};
/// @throws Error "<file>: <reason>" when a file is missing or unreadable.
[[nodiscard]] CellOfFolder read_cell_of(const std::filesystem::path& directory);

/// `cellmap security export`: exactly what one host of `role` needs, copied from the runtime folder
/// `directory` into `out` (new or empty; 0700): the CA certificates, the governance, the revocation list if
/// there is one and the role's folder (key 0600). No other role's key and no CA key.
/// @throws Error naming the path: a missing file, `out` not empty, a write failure.
void export_role(const std::filesystem::path& directory, Role role, const std::filesystem::path& out);

/// One more identity of a role for one host, so that hosts of the same role hold keys of their own and
/// each can be revoked alone: subject "CN=<role>@<host>,OU=<cell>,O=cellmap".
struct HostIdentity final {
  std::filesystem::path directory;  ///< the cell's runtime folder (its shared files are copied)
  Role role = Role::kPlanner;
  std::string host;    ///< 1-64 characters of [A-Za-z0-9._-]
  TopicGrants grants;  ///< the role's (transport::role_grants)
  std::chrono::system_clock::time_point valid_from;
  std::chrono::system_clock::time_point valid_until;  ///< never after the CAs' own end
  CaFolder ca;                                        ///< the CAs that issued the cell
  std::filesystem::path out;  ///< new or empty: what that host needs, as export_role() writes it
};
/// @throws Error as write_cell_credentials() does.
void issue_host_identity(const HostIdentity& request);

/// Revokes an identity the CAs of `ca` issued: adds its certificate to CA/revoked.crl (signed by the identity
/// CA, valid until the CA's own end) and copies that list into each runtime folder of `directories`. A
/// participant whose folder holds the list refuses that identity in the handshake; a revoked identity's own
/// folder with the list refuses to start. Revoking one identity twice changes nothing.
/// @returns the certificate's subject.
/// @throws Error naming the file: not a certificate of these CAs, a wrong passphrase, a write failure.
std::string revoke(const std::filesystem::path& certificate, const CaFolder& ca,
                   const std::vector<std::filesystem::path>& directories);

}  // namespace cellmap::security
