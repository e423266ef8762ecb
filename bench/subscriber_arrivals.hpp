#pragma once
// What the benchmarks that time DDS share: loopback-only Cyclone settings, and a subscriber process reporting
// each version it received to its parent, stamped on CLOCK_MONOTONIC (comparable across processes).

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>

namespace cellmap::bench {

/// Loopback unicast only, as in the tests; used when the caller did not configure Cyclone.
inline constexpr const char* kLoopbackConfig =
    "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface "
    "address=\"127.0.0.1\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
    "<Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery></Domain></CycloneDDS>";

/// Nanoseconds on std::chrono::steady_clock (CLOCK_MONOTONIC on Linux).
inline std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// What the subscriber process reports for each version it received.
struct Arrival {
  std::uint64_t version;
  std::int64_t received_ns;
};

/// In the subscriber process: writes the arrival of `version`, now, to stdout (a pipe to the parent); exits
/// if the parent is gone.
inline void report_arrival(std::uint64_t version) {
  const Arrival arrival{version, now_ns()};
  if (::write(STDOUT_FILENO, &arrival, sizeof arrival) != sizeof arrival) std::_Exit(3);
}

}  // namespace cellmap::bench
