// SPDX-License-Identifier: Apache-2.0
#include "cellmap/security/credentials.hpp"

#include <openssl/err.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <ctime>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "documents.hpp"
#include "openssl_util.hpp"

namespace cellmap::security {
namespace {

namespace fs = std::filesystem;
using TimePoint = std::chrono::system_clock::time_point;

constexpr std::array<const char*, 4> kRoleNames{"daemon", "planner", "robot", "tool"};
// Credential files are a few KB; anything much larger is a wrong path, not worth reading.
constexpr std::uintmax_t kMaxFileSize = 1 << 20;

std::string read_credential(const fs::path& file) {
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) throw Error(file.string() + ": " + ec.message());
  if (!fs::exists(status)) throw Error(file.string() + ": missing");
  if (!fs::is_regular_file(status)) throw Error(file.string() + ": not a regular file");
  if (fs::file_size(file, ec) > kMaxFileSize) throw Error(file.string() + ": over 1 MB, not a credential");
  return read_file(file);
}

ossl::X509Ptr load_certificate(const fs::path& file) {
  ossl::X509Ptr certificate = ossl::read_certificate(read_credential(file));
  if (!certificate) throw Error(file.string() + ": not a PEM certificate");
  return certificate;
}

void require_within(TimePoint from, TimePoint until, TimePoint now, const fs::path& file) {
  if (now < from) throw Error(file.string() + ": not valid before " + utc_text(from));
  if (now >= until) throw Error(file.string() + ": expired on " + utc_text(until));
}

// Returns when the certificate expires.
TimePoint require_current(const X509* certificate, const fs::path& file, TimePoint now) {
  const TimePoint until = ossl::to_time_point(X509_get0_notAfter(certificate));
  require_within(ossl::to_time_point(X509_get0_notBefore(certificate)), until, now, file);
  return until;
}

void require_issued_by(X509* certificate, const fs::path& file, X509* ca, const fs::path& ca_file) {
  if (X509_check_issued(ca, certificate) != X509_V_OK ||
      X509_verify(certificate, X509_get0_pubkey(ca)) != 1) {
    ERR_clear_error();
    throw Error(file.string() + ": not signed by the identity CA " + ca_file.string());
  }
}

void require_private_key_of(X509* certificate, const fs::path& file, const fs::path& certificate_file) {
  const std::string pem = read_credential(file);
  struct stat info {};
  if (::stat(file.c_str(), &info) == 0 && (info.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(info.st_mode & 07777));
    throw Error(file.string() + ": group or others have access (mode " + mode + "); chmod 600 it");
  }
  const ossl::KeyPtr key = ossl::read_private_key(pem);
  if (!key) throw Error(file.string() + ": not an unencrypted PEM private key");
  if (X509_check_private_key(certificate, key.get()) != 1) {
    ERR_clear_error();
    throw Error(file.string() + ": not the key of " + certificate_file.string());
  }
}

// The verified content of a signed document made for `domain`.
std::string load_document(const fs::path& file, X509* permissions_ca, const fs::path& ca_file,
                          std::uint32_t domain) {
  std::string content =
      verified_content(read_credential(file), permissions_ca, file.string(), ca_file.string());
  const std::optional<std::string> id = element_text(content, "id");
  if (!id || *id != std::to_string(domain)) {
    throw Error(file.string() + ": made for DDS domain " + id.value_or("(none)") + ", not " +
                std::to_string(domain));
  }
  return content;
}

// Returns when the permissions expire.
TimePoint require_permissions_for(const std::string& permissions, const std::string& subject,
                                  const fs::path& file, TimePoint now) {
  const std::string granted = element_text(permissions, "subject_name").value_or("(none)");
  if (granted != subject) throw Error(file.string() + ": made for " + granted + ", not for " + subject);
  const auto from = parse_utc(element_text(permissions, "not_before").value_or(""));
  const auto until = parse_utc(element_text(permissions, "not_after").value_or(""));
  if (!from || !until) throw Error(file.string() + ": validity: not in the form 2026-03-01T12:00:00Z");
  require_within(*from, *until, now, file);
  return *until;
}

// The cell a role's certificate is for: its subject's OU, as `security init` writes it.
std::string cell_of(const X509* certificate, const fs::path& file) {
  char cell[256] = {};
  const int n = X509_NAME_get_text_by_NID(X509_get_subject_name(certificate), NID_organizationalUnitName,
                                          cell, sizeof cell);
  if (n <= 0) throw Error(file.string() + ": the subject names no cell (OU)");
  return std::string(cell, static_cast<std::size_t>(n));
}

// The old layout kept the CA keys in ca/ of the runtime folder; a key copied by hand may sit beside the
// certificates.
void require_no_ca_key(const fs::path& directory) {
  for (const fs::path& folder : {directory / "ca", directory}) {
    for (const char* name : {"identity_ca_key.pem", "permissions_ca_key.pem"}) {
      std::error_code ec;
      if (fs::exists(folder / name, ec)) {
        throw Error((folder / name).string() +
                    ": a CA private key in the runtime folder: whoever reads this folder can issue "
                    "credentials for the cell; move it to the CA's own machine (docs/security.md, \"Where "
                    "keys live\")");
      }
    }
  }
}

// Returns when the list must be renewed, or `max` when there is none.
TimePoint require_not_revoked(X509* certificate, const RoleFiles& files, X509* identity_ca, TimePoint now) {
  std::error_code ec;
  if (!fs::exists(files.revocations, ec)) return TimePoint::max();
  const ossl::CrlPtr crl = ossl::read_crl(read_credential(files.revocations));
  if (!crl) throw Error(files.revocations.string() + ": not a PEM certificate revocation list");
  if (X509_CRL_verify(crl.get(), X509_get0_pubkey(identity_ca)) != 1) {
    ERR_clear_error();
    throw Error(files.revocations.string() + ": not signed by the identity CA " + files.identity_ca.string());
  }
  X509_REVOKED* entry = nullptr;
  if (X509_CRL_get0_by_serial(crl.get(), &entry, X509_get_serialNumber(certificate)) == 1) {
    throw Error(files.certificate.string() + ": revoked on " +
                utc_text(ossl::to_time_point(X509_REVOKED_get0_revocationDate(entry))) + " (" +
                files.revocations.string() + ")");
  }
  const ASN1_TIME* next_update = X509_CRL_get0_nextUpdate(crl.get());
  if (next_update == nullptr) return TimePoint::max();
  const TimePoint until = ossl::to_time_point(next_update);
  if (now >= until) throw Error(files.revocations.string() + ": expired on " + utc_text(until));
  return until;
}

}  // namespace

const char* to_string(Role role) {
  return kRoleNames.at(static_cast<std::size_t>(role));
}

Role parse_role(const std::string& name) {
  for (Role role : all_roles()) {
    if (name == to_string(role)) return role;
  }
  throw Error("role: '" + single_line(name) + "' is not one of daemon, planner, robot, tool");
}

const std::vector<Role>& all_roles() {
  static const std::vector<Role> roles{Role::kDaemon, Role::kPlanner, Role::kRobot, Role::kTool};
  return roles;
}

RoleFiles role_files(const fs::path& directory, Role role) {
  const fs::path own = directory / to_string(role);
  return {directory / "identity_ca.pem", directory / "permissions_ca.pem", directory / "governance.p7s",
          own / "identity.pem",          own / "identity_key.pem",         own / "permissions.p7s",
          directory / "revoked.crl"};
}

Credentials check(const Setting& setting, std::uint32_t domain, TimePoint now) {
  Credentials credentials;
  const RoleFiles& files = credentials.files = role_files(fs::absolute(setting.directory), setting.role);
  require_no_ca_key(fs::absolute(setting.directory));
  const ossl::X509Ptr identity_ca = load_certificate(files.identity_ca);
  TimePoint expires = require_current(identity_ca.get(), files.identity_ca, now);
  const ossl::X509Ptr permissions_ca = load_certificate(files.permissions_ca);
  expires = std::min(expires, require_current(permissions_ca.get(), files.permissions_ca, now));
  const ossl::X509Ptr certificate = load_certificate(files.certificate);
  expires = std::min(expires, require_current(certificate.get(), files.certificate, now));
  require_issued_by(certificate.get(), files.certificate, identity_ca.get(), files.identity_ca);
  require_private_key_of(certificate.get(), files.private_key, files.certificate);
  expires = std::min(expires, require_not_revoked(certificate.get(), files, identity_ca.get(), now));
  (void)load_document(files.governance, permissions_ca.get(), files.permissions_ca, domain);
  const std::string permissions =
      load_document(files.permissions, permissions_ca.get(), files.permissions_ca, domain);
  credentials.subject = ossl::subject_of(certificate.get());
  credentials.cell = cell_of(certificate.get(), files.certificate);
  expires =
      std::min(expires, require_permissions_for(permissions, credentials.subject, files.permissions, now));
  credentials.expires = expires;
  return credentials;
}

std::string utc_text(TimePoint time) {
  const std::time_t t = std::chrono::system_clock::to_time_t(time);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

}  // namespace cellmap::security
