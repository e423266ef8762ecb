// SPDX-License-Identifier: Apache-2.0
// A simulated cell's scene file (obstacles, robot, sensors, sweep plans), validated as load_scene does. The
// SCARA arm of config/scenes/ lies beside the input, so scenes may name it as a relative URDF path.
#include <filesystem>

#include "cellmap/sim/scene.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::filesystem::copy_file(CELLMAP_SOURCE_DIR "/config/scenes/scara.urdf",
                             cellmap::fuzz::scratch_directory() / "scara.urdf",
                             std::filesystem::copy_options::overwrite_existing);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  fuzz::accept_or_refuse([&] {
    (void)sim::parse_scene(fuzz::text(data, size), "cell.yaml", fuzz::scratch_directory().string());
  });
  return 0;
}
