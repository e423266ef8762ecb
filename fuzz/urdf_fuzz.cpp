// SPDX-License-Identifier: Apache-2.0
// A robot description (URDF) as the daemon's `robot` section and scenes load it: the chain to tool link
// "tool0" and its collision geometry (a mesh URI may name mesh.stl, a small STL beside the input, read with
// assimp). A robot that loads must pose its links.
#include <Eigen/Core>

#include <fstream>

#include "cellmap/urdf/urdf_model.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // One triangle, in STL's ASCII form.
  std::ofstream(cellmap::fuzz::scratch_directory() / "mesh.stl")
      << "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\nendloop\n"
         "endfacet\nendsolid t\n";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cellmap;
  fuzz::accept_or_refuse([&] {
    const UrdfModel model =
        UrdfModel::parse(fuzz::text(data, size), "robot.urdf", fuzz::scratch_directory().string());
    const Robot robot = model.robot("tool0");
    const std::vector<Eigen::Isometry3d> poses = robot.link_poses(Eigen::VectorXd::Zero(robot.dof()));
    if (poses.size() != robot.link_names().size() || !poses.back().matrix().allFinite()) std::abort();
  });
  return 0;
}
