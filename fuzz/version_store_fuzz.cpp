// SPDX-License-Identifier: Apache-2.0
// A state directory as the daemon finds it at start: the input up to its first NUL byte is the newest
// snapshot (environment-<version>.json, the boxes JSON plus cell, stamp, next box id and blob size/checksum),
// the rest its blob. VersionStore must load it or skip it as corrupt, never fail otherwise.
#include <algorithm>

#include "cellmap/environment/version_store.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  const std::string bytes = fuzz::text(data, size);
  const std::size_t split = std::min(bytes.find('\0'), bytes.size());
  const std::filesystem::path dir = fuzz::scratch_directory() / "state";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  fuzz::write_input("state/environment-00000000000000000007.json", bytes.substr(0, split));
  if (split < bytes.size())
    fuzz::write_input("state/environment-00000000000000000007.blob", bytes.substr(split + 1));
  fuzz::accept_or_refuse([&] {
    const VersionStore store(dir, "cell-1");
    const RecoveredState& recovered = store.recovered();
    // Loaded, or skipped with a reason; either way no version number and no box id is given out twice.
    if (recovered.environment.version() == 0 && recovered.problems.empty()) std::abort();
    if (store.next_version() <= 7) std::abort();
    for (const Box& box : recovered.environment.boxes()) {
      if (box.id >= store.next_box_id()) std::abort();
    }
  });
  return 0;
}
