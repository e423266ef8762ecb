// SPDX-License-Identifier: Apache-2.0
#include "documents.hpp"

#include <openssl/err.h>

#include <ctime>
#include <iomanip>
#include <sstream>

#include "cellmap/common/error.hpp"

namespace cellmap::security {
namespace {

constexpr const char* kHeader = R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" )";
constexpr const char* kGovernanceSchema =
    R"(xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">)";
constexpr const char* kPermissionsSchema =
    R"(xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">)";

void topic_list(std::ostringstream& xml, const char* element, const std::vector<std::string>& topics,
                const std::vector<std::string>& partitions) {
  if (topics.empty()) return;
  xml << "        <" << element << ">\n          <topics>\n";
  for (const std::string& topic : topics) xml << "            <topic>" << topic << "</topic>\n";
  xml << "          </topics>\n";
  if (!partitions.empty()) {
    xml << "          <partitions>\n";
    for (const std::string& partition : partitions)
      xml << "            <partition>" << partition << "</partition>\n";
    xml << "          </partitions>\n";
  }
  xml << "        </" << element << ">\n";
}

// The detail OpenSSL attached to its oldest error (PKCS7_verify puts the certificate check's reason there).
std::string error_detail() {
  const char* data = nullptr;
  int flags = 0;
  ERR_peek_error_data(&data, &flags);
  return (data != nullptr && (flags & ERR_TXT_STRING) != 0) ? std::string(data) : std::string();
}

}  // namespace

std::string governance_xml(std::uint32_t domain, const std::vector<std::string>& topics,
                           DataProtection data) {
  const char* data_kind = data == DataProtection::kEncrypt ? "ENCRYPT" : "SIGN";
  std::ostringstream xml;
  xml << kHeader << kGovernanceSchema << "\n"
      << "  <domain_access_rules>\n    <domain_rule>\n"
      << "      <domains>\n        <id>" << domain << "</id>\n      </domains>\n"
      << "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
      << "      <enable_join_access_control>true</enable_join_access_control>\n"
      << "      <discovery_protection_kind>SIGN</discovery_protection_kind>\n"
      << "      <liveliness_protection_kind>SIGN</liveliness_protection_kind>\n"
      << "      <rtps_protection_kind>NONE</rtps_protection_kind>\n"
      << "      <topic_access_rules>\n";
  for (const std::string& topic : topics) {
    xml << "        <topic_rule>\n"
        << "          <topic_expression>" << topic << "</topic_expression>\n"
        << "          <enable_discovery_protection>true</enable_discovery_protection>\n"
        << "          <enable_liveliness_protection>true</enable_liveliness_protection>\n"
        << "          <enable_read_access_control>true</enable_read_access_control>\n"
        << "          <enable_write_access_control>true</enable_write_access_control>\n"
        << "          <metadata_protection_kind>SIGN</metadata_protection_kind>\n"
        << "          <data_protection_kind>" << data_kind << "</data_protection_kind>\n"
        << "        </topic_rule>\n";
  }
  xml << "      </topic_access_rules>\n    </domain_rule>\n  </domain_access_rules>\n</dds>\n";
  return xml.str();
}

std::string permissions_xml(const std::string& grant_name, const std::string& subject, std::uint32_t domain,
                            std::chrono::system_clock::time_point valid_from,
                            std::chrono::system_clock::time_point valid_until, const TopicGrants& grants) {
  std::ostringstream xml;
  xml << kHeader << kPermissionsSchema << "\n"
      << "  <permissions>\n    <grant name=\"" << grant_name << "\">\n"
      << "      <subject_name>" << subject << "</subject_name>\n"
      << "      <validity>\n        <not_before>" << utc_text(valid_from) << "</not_before>\n"
      << "        <not_after>" << utc_text(valid_until) << "</not_after>\n      </validity>\n"
      << "      <allow_rule>\n        <domains>\n          <id>" << domain << "</id>\n        </domains>\n";
  topic_list(xml, "publish", grants.publish, grants.partitions);
  topic_list(xml, "subscribe", grants.subscribe, grants.partitions);
  xml << "      </allow_rule>\n      <default>DENY</default>\n    </grant>\n  </permissions>\n</dds>\n";
  return xml.str();
}

std::optional<std::string> element_text(const std::string& xml, const std::string& tag) {
  const std::string open = "<" + tag + ">";
  const std::size_t start = xml.find(open);
  if (start == std::string::npos) return std::nullopt;
  const std::size_t end = xml.find("</" + tag + ">", start + open.size());
  if (end == std::string::npos) return std::nullopt;
  return xml.substr(start + open.size(), end - start - open.size());
}

std::optional<std::chrono::system_clock::time_point> parse_utc(const std::string& text) {
  std::tm tm{};
  std::istringstream in(text);
  in >> std::get_time(&tm, "%Y-%m-%dT%H:%M:%SZ");
  if (in.fail() || text.size() != 20) return std::nullopt;
  return std::chrono::system_clock::from_time_t(timegm(&tm));
}

std::string sign_smime(const std::string& document, X509* signer, EVP_PKEY* key) {
  // Streaming: PKCS7_sign only prepares; SMIME_write_PKCS7 reads the content once, signs and writes it.
  constexpr int kFlags = PKCS7_DETACHED | PKCS7_TEXT | PKCS7_STREAM;
  const ossl::BioPtr content = ossl::memory_bio(document);
  const ossl::Pkcs7Ptr p7(PKCS7_sign(signer, key, nullptr, content.get(), kFlags));
  if (!p7) throw Error("OpenSSL: cannot sign a document: " + ossl::last_error());
  const ossl::BioPtr out = ossl::empty_bio();
  if (SMIME_write_PKCS7(out.get(), p7.get(), content.get(), kFlags) != 1)
    throw Error("OpenSSL: cannot write a signed document: " + ossl::last_error());
  return ossl::bio_text(out.get());
}

std::string verified_content(const std::string& smime, X509* ca, const std::string& file,
                             const std::string& ca_file) {
  const ossl::BioPtr in = ossl::memory_bio(smime);
  BIO* detached = nullptr;
  const ossl::Pkcs7Ptr p7(SMIME_read_PKCS7(in.get(), &detached));
  const ossl::BioPtr content(detached);
  if (!p7) throw Error(file + ": not an S/MIME signed document (" + ossl::last_error() + ")");
  const ossl::StorePtr store(X509_STORE_new());
  if (!store || X509_STORE_add_cert(store.get(), ca) != 1)
    throw Error("OpenSSL: cannot hold " + ca_file + ": " + ossl::last_error());
  const ossl::BioPtr out = ossl::empty_bio();
  if (PKCS7_verify(p7.get(), nullptr, store.get(), content.get(), out.get(), PKCS7_TEXT) != 1) {
    const int reason = ERR_GET_REASON(ERR_peek_error());
    const std::string detail = error_detail();
    const std::string what = ossl::last_error();
    if (reason == PKCS7_R_CERTIFICATE_VERIFY_ERROR) {
      throw Error(file + ": not signed by the permissions CA " + ca_file + " (" +
                  (detail.empty() ? what : detail) + ")");
    }
    throw Error(file + ": signature does not match the content (" + what + ")");
  }
  return ossl::bio_text(out.get());
}

}  // namespace cellmap::security
