// SPDX-License-Identifier: Apache-2.0
// A replay directory's depth intrinsics: the same bytes as intrinsics.yaml and as a PCL grabber .xml.
#include "cellmap/sensor/depth_io.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  const std::string bytes = fuzz::text(data, size);
  const std::filesystem::path yaml = fuzz::write_input("intrinsics.yaml", bytes);
  fuzz::accept_or_refuse([&] { (void)read_intrinsics_yaml(yaml.string()); });
  const std::filesystem::path xml = fuzz::write_input("frame.xml", bytes);
  fuzz::accept_or_refuse([&] { (void)read_pcl_intrinsics_xml(xml.string()); });
  return 0;
}
