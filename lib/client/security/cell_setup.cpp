// SPDX-License-Identifier: Apache-2.0
#include "cellmap/security/cell_setup.hpp"

#include <fcntl.h>
#include <openssl/bn.h>
#include <openssl/ec.h>
#include <openssl/err.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <set>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "documents.hpp"
#include "openssl_util.hpp"

namespace cellmap::security {
namespace {

namespace fs = std::filesystem;
using TimePoint = std::chrono::system_clock::time_point;

// Cell and host ids go into certificate subjects, which DDS Security's access control splits at ',', '/',
// '|' and '=': allow only characters that cannot be read as structure there or in XML.
bool is_plain_id(const std::string& id) {
  return !id.empty() && id.size() <= 64 && std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
}

struct Validity {
  TimePoint from;
  TimePoint until;
};

void require_plain(const std::string& id, const char* option) {
  if (!is_plain_id(id)) throw Error(std::string(option) + ": '" + id + "': use 1-64 of A-Z a-z 0-9 . _ -");
}

void require_empty_or_new(const fs::path& directory, const char* what) {
  std::error_code ec;
  if (fs::exists(directory, ec) && !fs::is_empty(directory, ec)) {
    throw Error(directory.string() + ": not empty; " + what +
                " are never overwritten (write a new set into a new directory)");
  }
}

// Whether `inner` is `outer` or inside it, by their absolute, normalised paths (neither need exist yet).
bool is_within(const fs::path& inner, const fs::path& outer) {
  const fs::path relative = fs::weakly_canonical(inner).lexically_relative(fs::weakly_canonical(outer));
  return !relative.empty() && *relative.begin() != "..";
}

void require_valid(const CellSetup& setup) {
  require_plain(setup.cell, "--cell");
  if (setup.domain > 232) throw Error("--domain: " + std::to_string(setup.domain) + " is not in 0-232");
  if (setup.valid_until <= setup.valid_from) throw Error("--days: the validity must end after it starts");
  for (Role role : all_roles()) {
    const auto grants = setup.grants.find(role);
    if (grants == setup.grants.end() || (grants->second.publish.empty() && grants->second.subscribe.empty()))
      throw Error(std::string("role ") + to_string(role) + ": no topics granted");
  }
  require_empty_or_new(setup.directory, "credentials");
  if (setup.ca.directory.empty()) throw Error("--ca: no CA folder given");
  if (is_within(setup.ca.directory, setup.directory) || is_within(setup.directory, setup.ca.directory)) {
    throw Error("--ca: " + setup.ca.directory.string() + ": the CA folder and the runtime folder " +
                setup.directory.string() + " must not hold one another (the CA keys never go to a host)");
  }
  if (setup.existing_ca) return;
  require_empty_or_new(setup.ca.directory, "CAs");
  if (setup.ca.passphrase.size() < kMinPassphraseLength)
    throw Error("CA passphrase: shorter than " + std::to_string(kMinPassphraseLength) + " bytes");
  if (setup.ca_valid_until < setup.valid_until)
    throw Error("--ca-days: the CAs must stay valid at least as long as the credentials they issue (--days)");
}

// Created with `mode` from the first byte: a private key is never readable by others, not even briefly.
void write_new_file(const fs::path& file, const std::string& text, mode_t mode) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
  if (fd < 0) throw Error(file.string() + ": cannot create: " + std::strerror(errno));
  bool ok = ::fchmod(fd, mode) == 0;  // exactly `mode`, whatever the umask
  for (std::size_t done = 0; ok && done < text.size();) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    ok = n > 0;
    if (ok) done += static_cast<std::size_t>(n);
  }
  ok = ok && ::fsync(fd) == 0;
  const int error = errno;
  ok = ::close(fd) == 0 && ok;
  if (!ok) throw Error(file.string() + ": cannot write: " + std::strerror(error));
}

// A new folder (parents too), or an empty one, that only its owner may enter, whatever the umask.
void make_private_directory(const fs::path& directory) {
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec || ::chmod(directory.c_str(), 0700) != 0)
    throw Error(directory.string() + ": cannot create: " + (ec ? ec.message() : std::strerror(errno)));
}

ossl::KeyPtr new_key() {
  ossl::KeyPtr key(EVP_EC_gen("P-256"));
  if (!key) throw Error("OpenSSL: cannot make a P-256 key: " + ossl::last_error());
  return key;
}

void add_extension(X509* certificate, X509V3_CTX* context, int nid, const char* value) {
  X509_EXTENSION* extension = X509V3_EXT_conf_nid(nullptr, context, nid, value);
  const bool ok = extension != nullptr && X509_add_ext(certificate, extension, -1) == 1;
  X509_EXTENSION_free(extension);
  if (!ok) throw Error(std::string("OpenSSL: cannot add ") + value + ": " + ossl::last_error());
}

void set_random_serial(X509* certificate) {
  BIGNUM* serial = BN_new();
  const bool ok = serial != nullptr && BN_rand(serial, 127, BN_RAND_TOP_ANY, BN_RAND_BOTTOM_ANY) == 1 &&
                  BN_to_ASN1_INTEGER(serial, X509_get_serialNumber(certificate)) != nullptr;
  BN_free(serial);
  if (!ok) throw Error("OpenSSL: cannot make a serial number: " + ossl::last_error());
}

struct Authority {
  ossl::KeyPtr key;
  ossl::X509Ptr certificate;
  std::string certificate_pem;
};

// A v3 certificate "CN=<name>,OU=<cell>,O=cellmap" for `key`: a CA (issuer nullptr: self-signed) or an
// identity.
ossl::X509Ptr make_certificate(const std::string& name, const std::string& cell, Validity validity,
                               EVP_PKEY* key, const Authority* issuer) {
  ossl::X509Ptr certificate(X509_new());
  if (!certificate) throw Error("OpenSSL: cannot make a certificate: " + ossl::last_error());
  X509* x = certificate.get();
  X509_set_version(x, X509_VERSION_3);
  set_random_serial(x);
  X509_NAME* subject = X509_get_subject_name(x);
  const auto add = [&](const char* field, const std::string& value) {
    X509_NAME_add_entry_by_txt(subject, field, MBSTRING_ASC,
                               reinterpret_cast<const unsigned char*>(value.c_str()), -1, -1, 0);
  };
  add("O", "cellmap");
  add("OU", cell);
  add("CN", name);
  const bool is_ca = issuer == nullptr;
  X509_set_issuer_name(x, is_ca ? subject : X509_get_subject_name(issuer->certificate.get()));
  ASN1_TIME_set(X509_getm_notBefore(x), std::chrono::system_clock::to_time_t(validity.from));
  ASN1_TIME_set(X509_getm_notAfter(x), std::chrono::system_clock::to_time_t(validity.until));
  X509_set_pubkey(x, key);
  X509V3_CTX context;
  X509V3_set_ctx_nodb(&context);
  X509V3_set_ctx(&context, is_ca ? x : issuer->certificate.get(), x, nullptr, nullptr, 0);
  add_extension(x, &context, NID_basic_constraints, is_ca ? "critical,CA:TRUE" : "critical,CA:FALSE");
  add_extension(x, &context, NID_key_usage,
                is_ca ? "critical,digitalSignature,keyCertSign,cRLSign" : "critical,digitalSignature");
  add_extension(x, &context, NID_subject_key_identifier, "hash");
  add_extension(x, &context, NID_authority_key_identifier, "keyid:always");
  if (X509_sign(x, is_ca ? key : issuer->key.get(), EVP_sha256()) <= 0)
    throw Error("OpenSSL: cannot sign a certificate: " + ossl::last_error());
  return certificate;
}

fs::path certificate_in(const CaFolder& ca, const std::string& name) {
  return ca.directory / (name + ".pem");
}
fs::path key_in(const CaFolder& ca, const std::string& name) {
  return ca.directory / (name + "_key.pem");
}
fs::path revocations_in(const fs::path& directory) {
  return directory / "revoked.crl";
}

Authority make_authority(const std::string& name, const std::string& cell, Validity validity,
                         const CaFolder& ca) {
  Authority authority{new_key(), nullptr, {}};
  authority.certificate = make_certificate(name, cell, validity, authority.key.get(), nullptr);
  authority.certificate_pem = ossl::certificate_pem(authority.certificate.get());
  write_new_file(key_in(ca, name), ossl::encrypted_private_key_pem(authority.key.get(), ca.passphrase), 0600);
  write_new_file(certificate_in(ca, name), authority.certificate_pem, 0644);
  return authority;
}

// One of the CAs of a CA folder, its key decrypted, valid now.
Authority load_authority(const std::string& name, const CaFolder& ca) {
  const fs::path certificate_file = certificate_in(ca, name);
  const fs::path key_file = key_in(ca, name);
  Authority authority{nullptr, nullptr, read_file(certificate_file)};
  authority.certificate = ossl::read_certificate(authority.certificate_pem);
  if (!authority.certificate) throw Error(certificate_file.string() + ": not a PEM certificate");
  const std::string key_pem = read_file(key_file);
  authority.key = ossl::read_private_key(key_pem, ca.passphrase);
  if (!authority.key) {
    throw Error(key_file.string() +
                (ossl::is_encrypted_key(key_pem) ? ": wrong CA passphrase" : ": not a PEM private key"));
  }
  if (X509_check_private_key(authority.certificate.get(), authority.key.get()) != 1)
    throw Error(key_file.string() + ": not the key of " + certificate_file.string());
  const TimePoint expires = ossl::to_time_point(X509_get0_notAfter(authority.certificate.get()));
  if (expires <= std::chrono::system_clock::now())
    throw Error(certificate_file.string() + ": expired on " + utc_text(expires) + "; issue with new CAs");
  return authority;
}

// Credentials never outlive the CAs that sign them: a participant would refuse them from that day on.
void require_within_authority(const Validity& validity, const Authority& authority, const fs::path& file) {
  const TimePoint expires = ossl::to_time_point(X509_get0_notAfter(authority.certificate.get()));
  if (validity.until > expires) {
    throw Error("--days: the credentials would stay valid until " + utc_text(validity.until) + ", after " +
                file.string() + " expires (" + utc_text(expires) + "): give fewer days, or new CAs");
  }
}

struct Authorities {
  Authority identity;
  Authority permissions;
};

// The CAs of an existing CA folder, when they outlive `validity`.
Authorities existing_authorities(const CaFolder& ca, Validity validity) {
  Authorities authorities{load_authority("identity_ca", ca), load_authority("permissions_ca", ca)};
  require_within_authority(validity, authorities.identity, certificate_in(ca, "identity_ca"));
  require_within_authority(validity, authorities.permissions, certificate_in(ca, "permissions_ca"));
  return authorities;
}

Authorities authorities_for(const CellSetup& setup, Validity validity) {
  if (!setup.existing_ca) {
    make_private_directory(setup.ca.directory);
    const Validity ca_validity{validity.from, setup.ca_valid_until};
    return {make_authority("identity_ca", setup.cell, ca_validity, setup.ca),
            make_authority("permissions_ca", setup.cell, ca_validity, setup.ca)};
  }
  return existing_authorities(setup.ca, validity);
}

// A document beside its signed form: DDS reads the .p7s, people the .xml.
void write_signed(const fs::path& signed_file, const std::string& document, const Authority& signer) {
  fs::path plain = signed_file;
  write_new_file(plain.replace_extension(".xml"), document, 0644);
  write_new_file(signed_file, sign_smime(document, signer.certificate.get(), signer.key.get()), 0644);
}

std::vector<std::string> granted_topics(const CellSetup& setup) {
  std::set<std::string> topics;
  for (const auto& [role, grants] : setup.grants) {
    topics.insert(grants.publish.begin(), grants.publish.end());
    topics.insert(grants.subscribe.begin(), grants.subscribe.end());
  }
  return {topics.begin(), topics.end()};
}

// Who one identity is and what it may do.
struct Identity {
  std::string name;  // the certificate's CN
  std::string cell;
  std::uint32_t domain;
  Validity validity;
  const TopicGrants& grants;
};

void write_identity(const Identity& identity, const RoleFiles& files, const Authorities& authorities) {
  make_private_directory(files.certificate.parent_path());
  const ossl::KeyPtr key = new_key();
  const ossl::X509Ptr certificate =
      make_certificate(identity.name, identity.cell, identity.validity, key.get(), &authorities.identity);
  write_new_file(files.private_key, ossl::private_key_pem(key.get()), 0600);
  write_new_file(files.certificate, ossl::certificate_pem(certificate.get()), 0644);
  const std::string grant = identity.cell + "." + identity.name;
  write_signed(files.permissions,
               permissions_xml(grant, ossl::subject_of(certificate.get()), identity.domain,
                               identity.validity.from, identity.validity.until, identity.grants),
               authorities.permissions);
}

void copy_file_as_new(const fs::path& from, const fs::path& to, mode_t mode) {
  write_new_file(to, read_file(from), mode);
}

// The CA certificates a runtime folder holds and the revocation list, if there is one.
void copy_ca_files(const CaFolder& ca, const fs::path& directory) {
  for (const char* name : {"identity_ca", "permissions_ca"})
    copy_file_as_new(certificate_in(ca, name), directory / (std::string(name) + ".pem"), 0644);
  if (fs::exists(revocations_in(ca.directory)))
    copy_file_as_new(revocations_in(ca.directory), revocations_in(directory), 0644);
}

// The files every host of a cell shares, from one runtime folder into another.
void copy_shared_files(const fs::path& from, const fs::path& to) {
  const RoleFiles source = role_files(from, Role::kDaemon);
  const RoleFiles target = role_files(to, Role::kDaemon);
  copy_file_as_new(source.identity_ca, target.identity_ca, 0644);
  copy_file_as_new(source.permissions_ca, target.permissions_ca, 0644);
  copy_file_as_new(source.governance, target.governance, 0644);
  if (fs::exists(source.revocations)) copy_file_as_new(source.revocations, target.revocations, 0644);
}

// The identity CA's certificate of a runtime folder must be the CA folder's: else what it issues is not
// trusted there.
void require_same_ca(const fs::path& directory, const Authority& identity_ca, const CaFolder& ca) {
  const fs::path file = role_files(directory, Role::kDaemon).identity_ca;
  if (read_file(file) != identity_ca.certificate_pem) {
    throw Error(file.string() + ": not the identity CA of " + ca.directory.string() +
                " (those CAs did not issue this cell)");
  }
}

ossl::CrlPtr load_or_start_revocations(const Authority& identity_ca, const CaFolder& ca) {
  const fs::path file = revocations_in(ca.directory);
  if (fs::exists(file)) {
    ossl::CrlPtr crl = ossl::read_crl(read_file(file));
    if (!crl) throw Error(file.string() + ": not a PEM certificate revocation list");
    return crl;
  }
  ossl::CrlPtr crl(X509_CRL_new());
  if (!crl || X509_CRL_set_version(crl.get(), 1) != 1 ||
      X509_CRL_set_issuer_name(crl.get(), X509_get_subject_name(identity_ca.certificate.get())) != 1)
    throw Error("OpenSSL: cannot make a revocation list: " + ossl::last_error());
  return crl;
}

// Adds `certificate` to the list (once) and signs it anew, valid until the CA itself expires.
void add_revoked(X509_CRL* crl, X509* certificate, const Authority& identity_ca) {
  X509_REVOKED* listed = nullptr;
  if (X509_CRL_get0_by_serial(crl, &listed, X509_get_serialNumber(certificate)) != 1) {
    X509_REVOKED* entry = X509_REVOKED_new();
    ASN1_TIME* now = ASN1_TIME_set(nullptr, std::time(nullptr));
    const bool ok = entry != nullptr && now != nullptr &&
                    X509_REVOKED_set_serialNumber(entry, X509_get_serialNumber(certificate)) == 1 &&
                    X509_REVOKED_set_revocationDate(entry, now) == 1 &&
                    X509_CRL_add0_revoked(crl, entry) == 1;
    ASN1_TIME_free(now);
    if (!ok) {
      X509_REVOKED_free(entry);
      throw Error("OpenSSL: cannot add to the revocation list: " + ossl::last_error());
    }
  }
  ASN1_TIME* now = ASN1_TIME_set(nullptr, std::time(nullptr));
  const bool ok = now != nullptr && X509_CRL_set1_lastUpdate(crl, now) == 1 &&
                  X509_CRL_set1_nextUpdate(crl, X509_get0_notAfter(identity_ca.certificate.get())) == 1 &&
                  X509_CRL_sort(crl) == 1 && X509_CRL_sign(crl, identity_ca.key.get(), EVP_sha256()) > 0;
  ASN1_TIME_free(now);
  if (!ok) throw Error("OpenSSL: cannot sign the revocation list: " + ossl::last_error());
}

}  // namespace

void write_cell_credentials(const CellSetup& setup) {
  require_valid(setup);
  make_private_directory(setup.directory);
  const Validity validity{setup.valid_from, setup.valid_until};
  const Authorities authorities = authorities_for(setup, validity);
  copy_ca_files(setup.ca, setup.directory);
  write_signed(setup.directory / "governance.p7s",
               governance_xml(setup.domain, granted_topics(setup), setup.data_protection),
               authorities.permissions);
  for (Role role : all_roles()) {
    write_identity({to_string(role), setup.cell, setup.domain, validity, setup.grants.at(role)},
                   role_files(setup.directory, role), authorities);
  }
}

CellOfFolder read_cell_of(const fs::path& directory) {
  const RoleFiles files = role_files(directory, Role::kDaemon);
  const ossl::X509Ptr certificate = ossl::read_certificate(read_file(files.certificate));
  if (!certificate) throw Error(files.certificate.string() + ": not a PEM certificate");
  char cell[256] = {};
  if (X509_NAME_get_text_by_NID(X509_get_subject_name(certificate.get()), NID_organizationalUnitName, cell,
                                sizeof cell) <= 0)
    throw Error(files.certificate.string() + ": the subject names no cell (OU)");
  fs::path governance = files.governance;
  const std::string id = element_text(read_file(governance.replace_extension(".xml")), "id").value_or("");
  if (id.empty() || id.size() > 3 || !std::all_of(id.begin(), id.end(), ::isdigit))
    throw Error(governance.string() + ": names no DDS domain");
  return {cell, static_cast<std::uint32_t>(std::stoul(id))};
}

void export_role(const fs::path& directory, Role role, const fs::path& out) {
  require_empty_or_new(out, "credentials");
  const RoleFiles source = role_files(directory, role);
  const RoleFiles target = role_files(out, role);
  make_private_directory(target.certificate.parent_path());
  copy_shared_files(directory, out);
  copy_file_as_new(source.certificate, target.certificate, 0644);
  copy_file_as_new(source.private_key, target.private_key, 0600);
  copy_file_as_new(source.permissions, target.permissions, 0644);
  ::chmod(out.c_str(), 0700);
}

void issue_host_identity(const HostIdentity& request) {
  require_plain(request.host, "--host");
  if (request.valid_until <= request.valid_from) throw Error("--days: the validity must end after it starts");
  require_empty_or_new(request.out, "credentials");
  const CellOfFolder cell = read_cell_of(request.directory);
  const Validity validity{request.valid_from, request.valid_until};
  const Authorities authorities = existing_authorities(request.ca, validity);
  require_same_ca(request.directory, authorities.identity, request.ca);
  make_private_directory(request.out);
  copy_shared_files(request.directory, request.out);
  write_identity({std::string(to_string(request.role)) + "@" + request.host, cell.cell, cell.domain, validity,
                  request.grants},
                 role_files(request.out, request.role), authorities);
}

std::string revoke(const fs::path& certificate_file, const CaFolder& ca,
                   const std::vector<fs::path>& directories) {
  const Authority identity_ca = load_authority("identity_ca", ca);
  const ossl::X509Ptr certificate = ossl::read_certificate(read_file(certificate_file));
  if (!certificate) throw Error(certificate_file.string() + ": not a PEM certificate");
  if (X509_check_issued(identity_ca.certificate.get(), certificate.get()) != X509_V_OK ||
      X509_verify(certificate.get(), X509_get0_pubkey(identity_ca.certificate.get())) != 1) {
    ERR_clear_error();
    throw Error(certificate_file.string() + ": not issued by the identity CA of " + ca.directory.string());
  }
  for (const fs::path& directory : directories) require_same_ca(directory, identity_ca, ca);
  const ossl::CrlPtr crl = load_or_start_revocations(identity_ca, ca);
  add_revoked(crl.get(), certificate.get(), identity_ca);
  const std::string pem = ossl::crl_pem(crl.get());
  write_file_atomically(revocations_in(ca.directory), pem);
  for (const fs::path& directory : directories) write_file_atomically(revocations_in(directory), pem);
  return ossl::subject_of(certificate.get());
}

}  // namespace cellmap::security
