// SPDX-License-Identifier: Apache-2.0
// A replay directory's poses.csv.
#include "cellmap/sensor/replay_source.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  const std::filesystem::path path = fuzz::write_input("poses.csv", fuzz::text(data, size));
  fuzz::accept_or_refuse([&] { (void)read_replay_poses(path.string()); });
  return 0;
}
