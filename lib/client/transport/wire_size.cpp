// SPDX-License-Identifier: Apache-2.0
#include "wire_size.hpp"

#include <dds/ddsi/ddsi_cdrstream.h>

#include "wire.hpp"

namespace cellmap::transport {

std::size_t wire::serialized_size(const void* sample, const dds_topic_descriptor_t& type) {
  constexpr std::size_t kEncapsulationHeader = 4;
  dds_ostream_t os;
  dds_ostream_init(&os, 0, 1);  // XCDR1, what @final types use
  dds_stream_write(&os, static_cast<const char*>(sample), type.m_ops);
  const std::size_t size = os.m_index;
  dds_ostream_fini(&os);
  return kEncapsulationHeader + size;
}

std::size_t wire_size(const Environment& env) {
  const wire::EnvironmentSample sample(env);
  return wire::serialized_size(sample.get(), cellmap_msg_Environment_desc);
}

std::size_t wire_size(const EnvironmentDelta& delta) {
  const wire::DeltaSample sample(delta);
  return wire::serialized_size(sample.get(), cellmap_msg_EnvironmentDelta_desc);
}

}  // namespace cellmap::transport
