// SPDX-License-Identifier: Apache-2.0
#pragma once
// The governance and permissions documents of DDS Security 1.1 (9.4.1.2.3 and 9.4.1.3), written for one cell,
// and their S/MIME signature (private to lib/client/security).

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/security/cell_setup.hpp"
#include "openssl_util.hpp"

namespace cellmap::security {

/// The domain's rules: only authenticated participants join (discovery and liveliness signed), every topic in
/// `topics` is access-controlled for reading and writing, its metadata signed and its data protected as
/// `data` says. Topics not listed cannot be created on the domain by a secured participant.
[[nodiscard]] std::string governance_xml(std::uint32_t domain, const std::vector<std::string>& topics,
                                         DataProtection data);

/// One grant for `subject` on `domain`, within [valid_from, valid_until]: the topics it may publish and
/// subscribe in its partitions; everything else denied.
[[nodiscard]] std::string permissions_xml(const std::string& grant_name, const std::string& subject,
                                          std::uint32_t domain,
                                          std::chrono::system_clock::time_point valid_from,
                                          std::chrono::system_clock::time_point valid_until,
                                          const TopicGrants& grants);

/// The text inside the first <tag>...</tag> of a document we wrote, or nullopt. Not an XML parser: enough for
/// the elements our own documents hold once, with no attributes or nesting of the same tag.
[[nodiscard]] std::optional<std::string> element_text(const std::string& xml, const std::string& tag);

/// "2026-03-01T12:00:00Z" back to a time point; nullopt when it is not in that form.
[[nodiscard]] std::optional<std::chrono::system_clock::time_point> parse_utc(const std::string& text);

/// The document as S/MIME multipart/signed (detached, text), signed by `signer` with `key`, the signer's
/// certificate included: what DDS Security's access control plugin reads.
[[nodiscard]] std::string sign_smime(const std::string& document, X509* signer, EVP_PKEY* key);

/// The signed content of an S/MIME document whose signature verifies against `ca`.
/// @throws Error "<file>: <reason>": not S/MIME, signed by another CA, or changed after signing.
[[nodiscard]] std::string verified_content(const std::string& smime, X509* ca, const std::string& file,
                                           const std::string& ca_file);

}  // namespace cellmap::security
