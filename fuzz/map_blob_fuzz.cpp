// SPDX-License-Identifier: Apache-2.0
// The map state the daemon saves with each version (header, viewpoint, the change detector's pending flips,
// OctoMap tree) and reads back at start; an unreadable one must be refused (the daemon then starts with an
// empty map). With the daemon's built-in pipeline settings.
#include "cellmap/cell/cell_pipeline.hpp"
#include "daemon_config.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  static const daemon::DaemonConfig config = daemon::DaemonConfig::parse("", "defaults", ".");
  fuzz::accept_or_refuse([&] {
    const CellPipeline pipeline(config.pipeline, {}, 1, fuzz::text(data, size));
    // A map that loaded must also save.
    (void)pipeline.map_state();
  });
  return 0;
}
