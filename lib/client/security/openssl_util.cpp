// SPDX-License-Identifier: Apache-2.0
#include "openssl_util.hpp"

#include <openssl/err.h>
#include <openssl/pem.h>

#include <algorithm>
#include <ctime>

#include "cellmap/common/error.hpp"

namespace cellmap::security::ossl {

std::string last_error() {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  if (code == 0) return "unknown reason";
  const char* reason = ERR_reason_error_string(code);
  return reason ? reason : "unknown reason";
}

BioPtr memory_bio(const std::string& text) {
  BioPtr bio(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
  if (!bio) throw Error("OpenSSL: cannot allocate a buffer: " + last_error());
  return bio;
}

BioPtr empty_bio() {
  BioPtr bio(BIO_new(BIO_s_mem()));
  if (!bio) throw Error("OpenSSL: cannot allocate a buffer: " + last_error());
  return bio;
}

std::string bio_text(BIO* bio) {
  char* data = nullptr;
  const long size = BIO_get_mem_data(bio, &data);
  return size > 0 ? std::string(data, static_cast<std::size_t>(size)) : std::string();
}

X509Ptr read_certificate(const std::string& pem) {
  const BioPtr bio = memory_bio(pem);
  X509Ptr certificate(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr));
  ERR_clear_error();
  return certificate;
}

KeyPtr read_private_key(const std::string& pem) {
  const BioPtr bio = memory_bio(pem);
  // An empty password callback: an encrypted key fails here instead of prompting on the terminal.
  const auto no_password = [](char*, int, int, void*) { return 0; };
  KeyPtr key(PEM_read_bio_PrivateKey(bio.get(), nullptr, no_password, nullptr));
  ERR_clear_error();
  return key;
}

CrlPtr read_crl(const std::string& pem) {
  const BioPtr bio = memory_bio(pem);
  CrlPtr crl(PEM_read_bio_X509_CRL(bio.get(), nullptr, nullptr, nullptr));
  ERR_clear_error();
  return crl;
}

KeyPtr read_private_key(const std::string& pem, const std::string& passphrase) {
  const BioPtr bio = memory_bio(pem);
  // With a callback-less read OpenSSL would take `u` as the passphrase, but a NUL byte would cut it.
  const auto give = [](char* buffer, int size, int, void* user) {
    const auto& text = *static_cast<const std::string*>(user);
    if (text.size() > static_cast<std::size_t>(size)) return 0;
    std::copy(text.begin(), text.end(), buffer);
    return static_cast<int>(text.size());
  };
  KeyPtr key(PEM_read_bio_PrivateKey(bio.get(), nullptr, give, const_cast<std::string*>(&passphrase)));
  ERR_clear_error();
  return key;
}

bool is_encrypted_key(const std::string& pem) {
  return pem.find("-----BEGIN ENCRYPTED PRIVATE KEY-----") != std::string::npos;
}

std::string certificate_pem(X509* certificate) {
  const BioPtr bio = empty_bio();
  if (PEM_write_bio_X509(bio.get(), certificate) != 1) throw Error("OpenSSL: " + last_error());
  return bio_text(bio.get());
}

std::string private_key_pem(EVP_PKEY* key) {
  const BioPtr bio = empty_bio();
  if (PEM_write_bio_PrivateKey(bio.get(), key, nullptr, nullptr, 0, nullptr, nullptr) != 1)
    throw Error("OpenSSL: " + last_error());
  return bio_text(bio.get());
}

std::string crl_pem(X509_CRL* crl) {
  const BioPtr bio = empty_bio();
  if (PEM_write_bio_X509_CRL(bio.get(), crl) != 1) throw Error("OpenSSL: " + last_error());
  return bio_text(bio.get());
}

std::string encrypted_private_key_pem(EVP_PKEY* key, const std::string& passphrase) {
  const BioPtr bio = empty_bio();
  if (PEM_write_bio_PKCS8PrivateKey(bio.get(), key, EVP_aes_256_cbc(), passphrase.data(),
                                    static_cast<int>(passphrase.size()), nullptr, nullptr) != 1)
    throw Error("OpenSSL: cannot encrypt a private key: " + last_error());
  return bio_text(bio.get());
}

std::string subject_of(const X509* certificate) {
  const BioPtr bio = empty_bio();
  X509_NAME_print_ex(bio.get(), X509_get_subject_name(certificate), 0, XN_FLAG_RFC2253);
  return bio_text(bio.get());
}

std::chrono::system_clock::time_point to_time_point(const ASN1_TIME* time) {
  std::tm tm{};
  if (ASN1_TIME_to_tm(time, &tm) != 1) throw Error("OpenSSL: unreadable time: " + last_error());
  return std::chrono::system_clock::from_time_t(timegm(&tm));
}

}  // namespace cellmap::security::ossl
