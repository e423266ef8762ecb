// SPDX-License-Identifier: Apache-2.0
// A point cloud file through load_cloud_file, as `cellmap segment` and the replay source read it. Built
// twice: CELLMAP_FUZZ_EXTENSION ".pcd" (target fuzz_pcd) and ".ply" (fuzz_ply).
#include "cellmap/io/cloud_file.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  const std::filesystem::path path =
      fuzz::write_input(std::string("input") + CELLMAP_FUZZ_EXTENSION, fuzz::text(data, size));
  fuzz::accept_or_refuse([&] {
    CloudFileOptions options;
    options.require_finite_points = false;  // the replay source's way: more of the file is read
    const CloudFile file = load_cloud_file(path, options);
    if (!file.labels.empty() && file.labels.size() != file.points.size()) std::abort();
  });
  return 0;
}
