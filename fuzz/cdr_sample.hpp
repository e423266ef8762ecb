// SPDX-License-Identifier: Apache-2.0
#pragma once
// A DDS sample as the receive path decodes it, for the harnesses of DDS inputs: Cyclone's checks of a
// received payload (encapsulation kind, dds_stream_normalize against the type's ops), then dds_stream_read
// into the generated struct, as a take() does. XCDR1 only: see dds_samples_fuzz.cpp for why XCDR2 is left
// out.

#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>
#include <dds/ddsi/q_protocol.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace cellmap::fuzz {

// A sample decoded into its generated struct; frees what Cyclone allocated inside it.
class Decoded {
 public:
  explicit Decoded(const dds_topic_descriptor_t& type) : type_(type), sample_(type.m_size, 0) {}
  ~Decoded() {
    if (filled_) dds_sample_free(sample_.data(), &type_, DDS_FREE_CONTENTS);
  }
  Decoded(const Decoded&) = delete;
  Decoded& operator=(const Decoded&) = delete;

  // Cyclone's checks of a received payload, then the read into the struct. False if Cyclone would drop it.
  bool decode(const std::uint8_t* data, std::size_t size) {
    if (size < 4) return false;
    std::uint16_t identifier = 0, options = 0;
    std::memcpy(&identifier, data, 2);
    std::memcpy(&options, data + 2, 2);
    // Final types travel as plain CDR: XCDR1 (CDR_LE/BE) or XCDR2 (CDR2_LE/BE, left out: see above).
    if (identifier != CDR_LE && identifier != CDR_BE) return false;
    const std::uint32_t xcdr = CDR_ENC_VERSION_1;
    const bool bswap = !CDR_ENC_IS_NATIVE(identifier);
    const std::uint32_t pad = ddsrt_fromBE2u(options) & 2;
    payload_.assign(reinterpret_cast<const char*>(data) + 4, reinterpret_cast<const char*>(data) + size);
    if (payload_.size() < pad) return false;
    std::uint32_t used = 0;
    if (dds_stream_normalize_data(payload_.data(), &used, static_cast<std::uint32_t>(payload_.size() - pad),
                                  bswap, xcdr, type_.m_ops) == nullptr) {
      return false;
    }
    dds_istream_t in;
    dds_istream_init(&in, used, payload_.data(), xcdr);
    dds_stream_read(&in, reinterpret_cast<char*>(sample_.data()), type_.m_ops);
    dds_istream_fini(&in);
    filled_ = true;
    return true;
  }
  template <typename Message>
  [[nodiscard]] const Message& as() const {
    return *reinterpret_cast<const Message*>(sample_.data());
  }

 private:
  const dds_topic_descriptor_t& type_;
  std::vector<unsigned char> sample_;
  std::string payload_;
  bool filled_ = false;
};

}  // namespace cellmap::fuzz
