// SPDX-License-Identifier: Apache-2.0
// The `cellmap` Python module: its error type and its parts (docs/python.md).
#include "bindings.hpp"
#include "cellmap/common/error.hpp"

PYBIND11_MODULE(cellmap, module) {
  namespace py = cellmap::python::py;
  module.doc() =
      "cellmap for Python planners: follow a cell's environment over DDS (EnvironmentSubscriber) and query "
      "it with the collision library (distance, batch_distance, spheres, PathChecker). Boxes are float64 "
      "arrays of 10: [cx, cy, cz, hx, hy, hz, qw, qx, qy, qz], metres, in the cell frame.";
  module.attr("__version__") = CELLMAP_VERSION;
  // Every refusal of the C++ side is about the input it was given (a file, a value, credentials): a
  // ValueError, so `except ValueError` catches bad arguments whichever side found them.
  py::register_exception<cellmap::Error>(module, "Error", PyExc_ValueError);
  cellmap::python::add_environment(module);
  cellmap::python::add_collision(module);
}
