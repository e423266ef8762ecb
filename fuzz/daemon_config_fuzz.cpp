// SPDX-License-Identifier: Apache-2.0
// cellmapd's configuration file (every section: source, occupancy, change, segment, reconcile).
#include "daemon_config.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  fuzz::accept_or_refuse([&] {
    (void)daemon::DaemonConfig::parse(fuzz::text(data, size), "cellmapd.yaml", fuzz::scratch_directory());
  });
  return 0;
}
