// SPDX-License-Identifier: Apache-2.0
// A URDF's mesh file read with assimp (load_mesh): the first byte picks the format by extension (.stl, .obj,
// .dae), the rest is the file. A mesh that loads must be valid (triangles, indices in range, finite corners).
#include "cellmap/urdf/mesh_file.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  if (size == 0) return 0;
  static const char* const kNames[] = {"mesh.stl", "mesh.obj", "mesh.dae"};
  const std::filesystem::path path =
      fuzz::write_input(kNames[data[0] % std::size(kNames)], fuzz::text(data + 1, size - 1));
  fuzz::accept_or_refuse([&] {
    const TriangleMesh mesh = load_mesh(path);
    try {
      mesh.validate("mesh");
    } catch (const Error& e) {
      std::fprintf(stderr, "load_mesh returned a broken mesh: %s\n", e.what());
      std::abort();
    }
  });
  return 0;
}
