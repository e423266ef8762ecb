// SPDX-License-Identifier: Apache-2.0
#pragma once
// DDS test setup: real participants on the loopback interface only, no multicast (lo has none), so tests
// run on machines without a network and do not leak traffic. Each test uses its own domain id (transport
// tests use 110-129) so concurrent tests do not see each other.

#include <chrono>
#include <cstdlib>
#include <string>

namespace cellmap::test {

/// Cyclone DDS 0.10 configuration for loopback-only unicast discovery; participants find each other by
/// probing participant indices on 127.0.0.1, and a participant silent for `lease` is gone.
inline std::string loopback_config(std::chrono::seconds lease) {
  return "<CycloneDDS><Domain Id=\"any\">"
         "<General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
         "<AllowMulticast>false</AllowMulticast></General>"
         "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>30</"
         "MaxAutoParticipantIndex>"
         "<Peers><Peer address=\"127.0.0.1\"/></Peers><LeaseDuration>" +
         std::to_string(lease.count()) + " s</LeaseDuration></Discovery></Domain></CycloneDDS>";
}

/// Sets CYCLONEDDS_URI for this process and the processes it starts. Call before the first participant.
/// A 1 s lease (default 10 s) lets tests see a killed process's writers expire.
inline void use_loopback() {
  ::setenv("CYCLONEDDS_URI", loopback_config(std::chrono::seconds(1)).c_str(), 1);
}

/// As use_loopback(), with Cyclone's default 10 s lease, for DDS Security: with a 1 s lease a process
/// starved for a second on a loaded machine loses its peers, and Cyclone DDS 0.10 does not always complete
/// the new security handshake then (cyclonedds#1895), which leaves the peers apart for good.
inline void use_secure_loopback() {
  ::setenv("CYCLONEDDS_URI", loopback_config(std::chrono::seconds(10)).c_str(), 1);
}

}  // namespace cellmap::test
