// SPDX-License-Identifier: Apache-2.0
// The segmentation config (config/segment.yaml, also cellmapd's `segment` section).
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  fuzz::accept_or_refuse(
      [&] { (void)SegmentConfig::from_yaml(YamlMap::parse(fuzz::text(data, size), "segment.yaml")); });
  return 0;
}
