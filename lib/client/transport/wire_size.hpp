// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal (tests and the dds benchmark): how many bytes an environment or a delta costs on the wire.

#include <cstddef>

#include "cellmap/environment/environment.hpp"

namespace cellmap::transport {

/// The serialized size of the sample as Cyclone DDS puts it in an RTPS DATA submessage: the 4-byte
/// encapsulation header plus the XCDR1 body, measured with Cyclone's own serializer. RTPS message and
/// submessage headers (about 60 bytes per sample) are not included.
[[nodiscard]] std::size_t wire_size(const Environment& env);
[[nodiscard]] std::size_t wire_size(const EnvironmentDelta& delta);

}  // namespace cellmap::transport
