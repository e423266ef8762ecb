#pragma once
// DDS test setup: real participants on the loopback interface only, no multicast (lo has none), so tests
// run on machines without a network and do not leak traffic. Each test uses its own domain id (transport
// tests use 110-129) so concurrent tests do not see each other.

#include <cstdlib>
#include <string>

namespace cellmap::test {

/// Cyclone DDS 0.10 configuration for loopback-only unicast discovery; participants find each other by
/// probing participant indices on 127.0.0.1. A 1 s lease (default 10 s) lets tests see a killed process's
/// writers expire.
inline const char* kLoopbackConfig =
    "<CycloneDDS><Domain Id=\"any\">"
    "<General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast></General>"
    "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>30</"
    "MaxAutoParticipantIndex>"
    "<Peers><Peer address=\"127.0.0.1\"/></Peers><LeaseDuration>1 s</LeaseDuration></Discovery>"
    "</Domain></CycloneDDS>";

/// Sets CYCLONEDDS_URI for this process and the processes it starts. Call before the first participant.
inline void use_loopback() {
  ::setenv("CYCLONEDDS_URI", kLoopbackConfig, 1);
}

}  // namespace cellmap::test
