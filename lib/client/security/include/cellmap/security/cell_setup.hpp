// SPDX-License-Identifier: Apache-2.0
#pragma once
// `cellmap security init`: everything one cell needs for DDS Security, made with OpenSSL (the layout is in
// credentials.hpp). Two CAs (identity, permissions; ECDSA P-256, SHA-256), one identity per role, the
// governance document and one permissions document per role, both S/MIME-signed by the permissions CA as the
// DDS Security specification (1.1, 9.4.1.2–3) requires.

#include <chrono>
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

struct CellSetup final {
  std::filesystem::path directory;  ///< created (parents too); must not exist or be empty
  std::string cell;                 ///< 1-64 characters of [A-Za-z0-9._-]: it goes into certificate subjects
  std::uint32_t domain = 0;         ///< the only DDS domain the documents allow, 0-232
  std::chrono::system_clock::time_point valid_from;   ///< certificates and permissions, both
  std::chrono::system_clock::time_point valid_until;  ///< after valid_from
  std::map<Role, TopicGrants> grants;                 ///< every role's; the governance covers their topics
  DataProtection data_protection = DataProtection::kEncrypt;
  /// Empty: new CAs for this cell alone (its participants talk to no other cell's). Otherwise the
  /// credentials directory of another cell of the same plant, holding its CA certificates and ca/ keys:
  /// this cell's identities and documents are issued by those CAs, so the plant's participants
  /// authenticate each other, while each cell's permissions still grant only its own partitions.
  std::filesystem::path plant_ca;
};

/// Writes the credentials of `setup.cell` into `setup.directory`: private keys with mode 0600 (created so,
/// never wider for an instant), the role and CA folders 0700, the rest 0644. With `plant_ca` the CA
/// certificates are copied from there and no ca/ folder is written (the plant's CA keys stay in one place). The plain XML of each signed
/// document is written beside it (`.xml`) for reading; DDS reads only the signed one.
/// @throws Error naming the option or path: bad cell id, domain or validity, a role without grants, a
/// directory that is not empty, a plant CA directory without its CA certificates and keys (or a key that is
/// not its certificate's), a write or OpenSSL failure (the directory may then hold part of the set).
void write_cell_credentials(const CellSetup& setup);

}  // namespace cellmap::security
