// SPDX-License-Identifier: Apache-2.0
// A replay frame's depth image: the first byte picks PNG (even) or TIFF (odd), the rest is the file.
#include "cellmap/sensor/depth_io.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  if (size == 0) return 0;
  const std::string name = data[0] % 2 == 0 ? "frame_depth.png" : "frame_depth.tiff";
  const std::filesystem::path path = fuzz::write_input(name, fuzz::text(data + 1, size - 1));
  fuzz::accept_or_refuse([&] {
    const RawDepth image = read_depth_image(path.string());
    if (image.depth.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height))
      std::abort();
  });
  return 0;
}
