// SPDX-License-Identifier: Apache-2.0
#include "cellmap/security/cell_setup.hpp"

#include <fcntl.h>
#include <openssl/bn.h>
#include <openssl/ec.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <set>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "documents.hpp"
#include "openssl_util.hpp"

namespace cellmap::security {
namespace {

namespace fs = std::filesystem;
using TimePoint = std::chrono::system_clock::time_point;

// Cell ids go into certificate subjects, which DDS Security's access control splits at ',', '/', '|' and
// '=': allow only characters that cannot be read as structure there or in XML.
bool is_plain_id(const std::string& id) {
  return !id.empty() && id.size() <= 64 && std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
}

void require_valid(const CellSetup& setup) {
  if (!is_plain_id(setup.cell)) throw Error("--cell: '" + setup.cell + "': use 1-64 of A-Z a-z 0-9 . _ -");
  if (setup.domain > 232) throw Error("--domain: " + std::to_string(setup.domain) + " is not in 0-232");
  if (setup.valid_until <= setup.valid_from) throw Error("--days: the validity must end after it starts");
  for (Role role : all_roles()) {
    const auto grants = setup.grants.find(role);
    if (grants == setup.grants.end() || (grants->second.publish.empty() && grants->second.subscribe.empty()))
      throw Error(std::string("role ") + to_string(role) + ": no topics granted");
  }
  std::error_code ec;
  if (fs::exists(setup.directory, ec) && !fs::is_empty(setup.directory, ec)) {
    throw Error(setup.directory.string() +
                ": not empty; credentials are never overwritten (write a new set into a new directory)");
  }
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

void make_private_directory(const fs::path& directory) {
  if (::mkdir(directory.c_str(), 0700) != 0 || ::chmod(directory.c_str(), 0700) != 0)
    throw Error(directory.string() + ": cannot create: " + std::strerror(errno));
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

struct Issuer {
  X509* certificate;  // nullptr: self-signed
  EVP_PKEY* key;
};

// A v3 certificate "CN=<name>,OU=<cell>,O=cellmap" for `key`: a CA (self-signed) or an identity.
ossl::X509Ptr make_certificate(const std::string& name, const CellSetup& setup, EVP_PKEY* key,
                               Issuer issuer) {
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
  add("OU", setup.cell);
  add("CN", name);
  const bool is_ca = issuer.certificate == nullptr;
  X509_set_issuer_name(x, is_ca ? subject : X509_get_subject_name(issuer.certificate));
  ASN1_TIME_set(X509_getm_notBefore(x), std::chrono::system_clock::to_time_t(setup.valid_from));
  ASN1_TIME_set(X509_getm_notAfter(x), std::chrono::system_clock::to_time_t(setup.valid_until));
  X509_set_pubkey(x, key);
  X509V3_CTX context;
  X509V3_set_ctx_nodb(&context);
  X509V3_set_ctx(&context, is_ca ? x : issuer.certificate, x, nullptr, nullptr, 0);
  add_extension(x, &context, NID_basic_constraints, is_ca ? "critical,CA:TRUE" : "critical,CA:FALSE");
  add_extension(x, &context, NID_key_usage,
                is_ca ? "critical,digitalSignature,keyCertSign,cRLSign" : "critical,digitalSignature");
  add_extension(x, &context, NID_subject_key_identifier, "hash");
  add_extension(x, &context, NID_authority_key_identifier, "keyid:always");
  if (X509_sign(x, is_ca ? key : issuer.key, EVP_sha256()) <= 0)
    throw Error("OpenSSL: cannot sign a certificate: " + ossl::last_error());
  return certificate;
}

struct Authority {
  ossl::KeyPtr key;
  ossl::X509Ptr certificate;
};

Authority make_authority(const std::string& name, const CellSetup& setup) {
  Authority ca{new_key(), nullptr};
  ca.certificate = make_certificate(name, setup, ca.key.get(), {nullptr, nullptr});
  write_new_file(setup.directory / "ca" / (name + "_key.pem"), ossl::private_key_pem(ca.key.get()), 0600);
  write_new_file(setup.directory / (name + ".pem"), ossl::certificate_pem(ca.certificate.get()), 0644);
  return ca;
}

// One of the plant's CAs, read from another cell's credentials directory; its certificate is copied.
Authority plant_authority(const std::string& name, const CellSetup& setup) {
  const fs::path certificate_file = setup.plant_ca / (name + ".pem");
  const fs::path key_file = setup.plant_ca / "ca" / (name + "_key.pem");
  const std::string certificate_pem = read_file(certificate_file);
  Authority ca{ossl::read_private_key(read_file(key_file)), ossl::read_certificate(certificate_pem)};
  if (!ca.certificate) throw Error(certificate_file.string() + ": not a PEM certificate");
  if (!ca.key) throw Error(key_file.string() + ": not an unencrypted PEM private key");
  if (X509_check_private_key(ca.certificate.get(), ca.key.get()) != 1)
    throw Error(key_file.string() + ": not the key of " + certificate_file.string());
  write_new_file(setup.directory / (name + ".pem"), certificate_pem, 0644);
  return ca;
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

void write_role(Role role, const CellSetup& setup, const Authority& identity_ca,
                const Authority& permissions_ca) {
  const RoleFiles files = role_files(setup.directory, role);
  make_private_directory(files.certificate.parent_path());
  const ossl::KeyPtr key = new_key();
  const ossl::X509Ptr certificate = make_certificate(to_string(role), setup, key.get(),
                                                     {identity_ca.certificate.get(), identity_ca.key.get()});
  write_new_file(files.private_key, ossl::private_key_pem(key.get()), 0600);
  write_new_file(files.certificate, ossl::certificate_pem(certificate.get()), 0644);
  const std::string grant = setup.cell + "." + to_string(role);
  write_signed(files.permissions,
               permissions_xml(grant, ossl::subject_of(certificate.get()), setup.domain, setup.valid_from,
                               setup.valid_until, setup.grants.at(role)),
               permissions_ca);
}

}  // namespace

void write_cell_credentials(const CellSetup& setup) {
  require_valid(setup);
  std::error_code ec;
  fs::create_directories(setup.directory, ec);
  if (ec) throw Error(setup.directory.string() + ": cannot create: " + ec.message());
  const bool new_cas = setup.plant_ca.empty();
  if (new_cas) make_private_directory(setup.directory / "ca");
  const Authority identity_ca =
      new_cas ? make_authority("identity_ca", setup) : plant_authority("identity_ca", setup);
  const Authority permissions_ca =
      new_cas ? make_authority("permissions_ca", setup) : plant_authority("permissions_ca", setup);
  write_signed(setup.directory / "governance.p7s",
               governance_xml(setup.domain, granted_topics(setup), setup.data_protection), permissions_ca);
  for (Role role : all_roles()) write_role(role, setup, identity_ca, permissions_ca);
}

}  // namespace cellmap::security
