// SPDX-License-Identifier: Apache-2.0
#pragma once
// OpenSSL objects owned by unique_ptr, and the conversions the credential check and the setup share
// (private to lib/client/security).

#include <openssl/bio.h>
#include <openssl/evp.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>

#include <chrono>
#include <memory>
#include <string>

namespace cellmap::security::ossl {

template <class T, void (*Release)(T*)>
struct Free final {
  void operator()(T* p) const { Release(p); }
};
using X509Ptr = std::unique_ptr<X509, Free<X509, X509_free>>;
using KeyPtr = std::unique_ptr<EVP_PKEY, Free<EVP_PKEY, EVP_PKEY_free>>;
using BioPtr = std::unique_ptr<BIO, Free<BIO, BIO_free_all>>;
using Pkcs7Ptr = std::unique_ptr<PKCS7, Free<PKCS7, PKCS7_free>>;
using StorePtr = std::unique_ptr<X509_STORE, Free<X509_STORE, X509_STORE_free>>;
using CrlPtr = std::unique_ptr<X509_CRL, Free<X509_CRL, X509_CRL_free>>;

/// The reason of the oldest OpenSSL error queued (e.g. "unable to get local issuer certificate"), or
/// "unknown reason"; empties the queue so the next call starts clean.
[[nodiscard]] std::string last_error();

/// A read-only memory BIO over `text` (which must outlive it).
[[nodiscard]] BioPtr memory_bio(const std::string& text);
/// An empty writable memory BIO, and what was written into one.
[[nodiscard]] BioPtr empty_bio();
[[nodiscard]] std::string bio_text(BIO* bio);

/// nullptr when `pem` holds no PEM certificate (resp. unencrypted PEM private key, CRL).
[[nodiscard]] X509Ptr read_certificate(const std::string& pem);
[[nodiscard]] KeyPtr read_private_key(const std::string& pem);
[[nodiscard]] CrlPtr read_crl(const std::string& pem);
/// A PEM private key, encrypted or not, read with `passphrase`; nullptr when it is not one or the
/// passphrase is wrong.
[[nodiscard]] KeyPtr read_private_key(const std::string& pem, const std::string& passphrase);
/// True when `pem` is an encrypted PKCS#8 private key ("ENCRYPTED PRIVATE KEY").
[[nodiscard]] bool is_encrypted_key(const std::string& pem);
[[nodiscard]] std::string certificate_pem(X509* certificate);
[[nodiscard]] std::string crl_pem(X509_CRL* crl);
[[nodiscard]] std::string private_key_pem(EVP_PKEY* key);
/// PKCS#8, AES-256-CBC with a key derived from `passphrase` (PBKDF2, OpenSSL's defaults).
[[nodiscard]] std::string encrypted_private_key_pem(EVP_PKEY* key, const std::string& passphrase);

/// The subject as DDS Security's access control prints it (RFC 2253, e.g. "CN=daemon,OU=cell-1,O=cellmap"):
/// the permissions document must name it exactly so.
[[nodiscard]] std::string subject_of(const X509* certificate);

[[nodiscard]] std::chrono::system_clock::time_point to_time_point(const ASN1_TIME* time);

}  // namespace cellmap::security::ossl
