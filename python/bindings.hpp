// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the binding files of the `cellmap` module share: the registration of each part, and the conversions
// of boxes between NumPy arrays and the C++ types (internal to python/).
//
// A box on the Python side is 10 float64 values, [cx, cy, cz, hx, hy, hz, qw, qx, qy, qz]: centre and half
// extents in metres, rotation R_CB as a unit quaternion (the form `cellmap distance` takes). Arrays of boxes
// have the 10 values last: shape (10,), (N, 10) or (K, N, 10).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "cellmap/collision/obb.hpp"

namespace cellmap::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

void add_environment(py::module_& module);
void add_collision(py::module_& module);

/// The boxes of `array` (last axis of 10), as collision boxes, in C order of the leading axes.
/// @throws py::value_error naming `name`: another shape, a value that is not finite, a negative half
/// extent, a quaternion whose norm differs from 1 by more than 1e-6.
[[nodiscard]] std::vector<collision::Obb> obbs_of(const DoubleArray& array, const std::string& name);

/// The boxes as one (N, 10) array, in their order.
[[nodiscard]] DoubleArray boxes_array(const std::vector<Box>& boxes);

/// A new float64 array of `shape`, C order.
[[nodiscard]] DoubleArray new_array(const std::vector<py::ssize_t>& shape);

}  // namespace cellmap::python
