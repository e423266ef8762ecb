// SPDX-License-Identifier: Apache-2.0
// The collision library for Python: box-box signed distance, the batch of robot boxes × environment boxes
// (arrays in and out, the GIL released), the paper's spheres and the path check of a robot from its URDF.
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "bindings.hpp"
#include "cellmap/collision/batch.hpp"
#include "cellmap/collision/box_distance.hpp"
#include "cellmap/collision/robot_boxes.hpp"
#include "cellmap/collision/spheres.hpp"
#include "cellmap/environment/environment.hpp"
#include "cellmap/planning/bspline.hpp"
#include "cellmap/planning/path_check.hpp"
#include "cellmap/urdf/urdf_model.hpp"

namespace cellmap::python {

DoubleArray new_array(const std::vector<py::ssize_t>& shape) {
  return DoubleArray(shape);
}

std::vector<collision::Obb> obbs_of(const DoubleArray& array, const std::string& name) {
  if (array.ndim() < 1 || array.shape(array.ndim() - 1) != 10) {
    std::string shape;
    for (py::ssize_t i = 0; i < array.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(array.shape(i));
    throw py::value_error(name +
                          ": boxes are arrays of 10 values [cx, cy, cz, hx, hy, hz, qw, qx, qy, qz] "
                          "(the last axis), not of shape (" +
                          shape + ")");
  }
  const double* v = array.data();
  std::vector<collision::Obb> obbs(static_cast<std::size_t>(array.size() / 10));
  for (std::size_t i = 0; i < obbs.size(); ++i, v += 10) {
    const std::string where = name + "[" + std::to_string(i) + "]";
    for (int k = 0; k < 10; ++k)
      if (!std::isfinite(v[k])) throw py::value_error(where + ": not a finite number");
    if (v[3] < 0 || v[4] < 0 || v[5] < 0) throw py::value_error(where + ": a half extent is negative");
    const Eigen::Quaterniond q(v[6], v[7], v[8], v[9]);
    if (std::abs(q.norm() - 1.0) > 1e-6)
      throw py::value_error(where + ": the rotation is not a unit quaternion");
    Box box;
    box.center = {v[0], v[1], v[2]};
    box.half_extents = {v[3], v[4], v[5]};
    box.rotation = q;
    obbs[i] = collision::to_obb(box);
  }
  return obbs;
}

namespace {

collision::Obb one_box(const DoubleArray& array, const std::string& name) {
  if (array.ndim() != 1) throw py::value_error(name + ": one box is 10 values, an array of shape (10,)");
  return obbs_of(array, name).at(0);
}

py::array_t<double> vector_array(const Eigen::Vector3d& v) {
  py::array_t<double> out(3);
  std::copy(v.data(), v.data() + 3, out.mutable_data());
  return out;
}

// The checkpoints of `robot`: (R, 10) is one, (K, R, 10) K of them.
std::vector<std::vector<collision::Obb>> robot_at_checkpoints(const DoubleArray& robot) {
  if (robot.ndim() != 2 && robot.ndim() != 3)
    throw py::value_error("robot: boxes of shape (R, 10) or (K, R, 10) (K checkpoints of R boxes)");
  const std::vector<collision::Obb> all = obbs_of(robot, "robot");
  const std::size_t per = static_cast<std::size_t>(robot.shape(robot.ndim() - 2));
  std::vector<std::vector<collision::Obb>> out;
  for (std::size_t k = 0; per > 0 && k < all.size() / per; ++k)
    out.emplace_back(all.begin() + static_cast<std::ptrdiff_t>(k * per),
                     all.begin() + static_cast<std::ptrdiff_t>((k + 1) * per));
  return out;
}

// `out[key]` if it is a writable C-ordered float64 array of `shape`, else a new one (none given).
DoubleArray output_array(const std::optional<py::dict>& out, const char* key,
                         const std::vector<py::ssize_t>& shape) {
  if (!out) return new_array(shape);
  if (!out->contains(key)) throw py::value_error(std::string("out: no array '") + key + "'");
  const py::object given = (*out)[key];
  if (!py::isinstance<py::array_t<double>>(given))
    throw py::value_error(std::string("out['") + key + "']: not a float64 array");
  auto array = py::reinterpret_borrow<py::array_t<double>>(given);
  const bool fits = array.ndim() == static_cast<py::ssize_t>(shape.size()) &&
                    std::equal(shape.begin(), shape.end(), array.shape()) &&
                    (array.flags() & py::array::c_style) != 0 && array.writeable();
  if (!fits)
    throw py::value_error(std::string("out['") + key +
                          "']: not a writable C-ordered array of the result's shape");
  return array;
}

// The dense constraints as arrays: the robot's leading axes, then the environment's boxes. Written into `out`
// when given (a planner's loop reuses its arrays: fresh ones cost their first touch of memory each call).
py::dict batch_distance(const DoubleArray& robot, const DoubleArray& environment,
                        std::optional<py::dict> out) {
  const std::vector<std::vector<collision::Obb>> checkpoints = robot_at_checkpoints(robot);
  if (environment.ndim() != 2) throw py::value_error("environment: boxes of shape (E, 10)");
  const std::vector<collision::Obb> env = obbs_of(environment, "environment");
  std::vector<py::ssize_t> shape(robot.shape(), robot.shape() + robot.ndim() - 1);
  shape.push_back(static_cast<py::ssize_t>(env.size()));
  std::vector<py::ssize_t> point_shape = shape;
  point_shape.push_back(3);
  DoubleArray distance = output_array(out, "distance", shape),
              point_a = output_array(out, "point_a", point_shape),
              point_b = output_array(out, "point_b", point_shape),
              normal = output_array(out, "normal", point_shape);
  const collision::ConstraintArrays arrays{distance.mutable_data(), point_a.mutable_data(),
                                           point_b.mutable_data(), normal.mutable_data()};
  {
    py::gil_scoped_release release;
    collision::constraints_into(checkpoints, env, arrays);
  }
  py::dict result = out ? *out : py::dict();
  result["distance"] = distance;
  result["point_a"] = point_a;
  result["point_b"] = point_b;
  result["normal"] = normal;
  return result;
}

// The anchor of the Python batch benchmark: the same C++ batch, timed in C++ without any conversion.
double batch_distance_seconds(const DoubleArray& robot, const DoubleArray& environment, int repeats) {
  if (repeats < 1) throw py::value_error("repeats: must be at least 1");
  const std::vector<std::vector<collision::Obb>> checkpoints = robot_at_checkpoints(robot);
  const std::vector<collision::Obb> env = obbs_of(environment, "environment");
  py::gil_scoped_release release;
  double smallest = 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < repeats; ++i) smallest += collision::constraints(checkpoints, env).min_distance();
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  if (std::isnan(smallest)) throw py::value_error("no distance");  // keeps the loop from being optimised away
  return elapsed.count() / repeats;
}

py::array_t<double> sphere_cover(const DoubleArray& box, int n) {
  if (n < 1) throw py::value_error("n: at least one sphere");
  const std::vector<collision::Sphere> spheres = collision::sphere_cover(one_box(box, "box"), n);
  py::array_t<double> out({static_cast<py::ssize_t>(spheres.size()), py::ssize_t{4}});
  auto view = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    for (int c = 0; c < 3; ++c) view(static_cast<py::ssize_t>(i), c) = spheres[i].center[c];
    view(static_cast<py::ssize_t>(i), 3) = spheres[i].radius;
  }
  return out;
}

std::vector<collision::Sphere> spheres_of(const DoubleArray& array, const std::string& name) {
  if (array.ndim() != 2 || array.shape(1) != 4)
    throw py::value_error(name + ": spheres of shape (N, 4) [cx, cy, cz, r]");
  std::vector<collision::Sphere> spheres(static_cast<std::size_t>(array.shape(0)));
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const double* v = array.data() + 4 * i;
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]) || !std::isfinite(v[3]) ||
        v[3] < 0)
      throw py::value_error(name + "[" + std::to_string(i) + "]: not a finite centre and radius >= 0");
    spheres[i] = {Eigen::Vector3d(v[0], v[1], v[2]), v[3]};
  }
  return spheres;
}

// A robot from its URDF, with a box on each collision shape of its links, and the path check of the C++
// planners (planning::path_blocked).
class PathChecker final {
 public:
  PathChecker(const std::string& urdf, const std::string& tool_link)
      : robot_(UrdfModel::load(urdf).robot(tool_link)) {}

  [[nodiscard]] int dof() const { return robot_.robot().dof(); }
  [[nodiscard]] int boxes() const { return robot_.size(); }

  DoubleArray place(const DoubleArray& q) const {
    std::vector<Box> boxes;
    for (const collision::Obb& obb : robot_.place(joints_of(q))) boxes.push_back(collision::to_box(obb));
    return boxes_array(boxes);
  }

  std::optional<py::dict> blocked(const DoubleArray& control_points, const Environment& environment,
                                  int checkpoints, double margin, bool ignore_unknown) const {
    if (control_points.ndim() != 2 || control_points.shape(1) != dof())
      throw py::value_error("control_points: shape (M, " + std::to_string(dof()) +
                            "), one joint vector a row");
    if (checkpoints < 1) throw py::value_error("checkpoints: at least 1");
    if (!(margin >= 0)) throw py::value_error("margin: must be >= 0 metres");
    std::vector<Eigen::VectorXd> points;
    for (py::ssize_t i = 0; i < control_points.shape(0); ++i)
      points.emplace_back(Eigen::Map<const Eigen::VectorXd>(control_points.data() + i * dof(), dof()));
    planning::Blocking blocking;
    {
      py::gil_scoped_release release;
      const planning::BSplinePath path(std::move(points));
      const planning::PathEnvironment boxes(environment.boxes(), {ignore_unknown});
      blocking = planning::path_blocked(robot_, path, checkpoints, boxes, margin);
    }
    if (!blocking.blocked) return std::nullopt;
    py::dict out;
    out["checkpoint"] = blocking.checkpoint;
    out["t"] = blocking.t;
    out["robot_box"] = blocking.robot_box;
    out["box_id"] = blocking.box_id;
    out["unknown"] = blocking.space == BoxSpace::kUnknown;
    out["distance"] = blocking.distance;
    out["point"] = vector_array(blocking.point);
    return out;
  }

 private:
  Eigen::VectorXd joints_of(const DoubleArray& q) const {
    if (q.ndim() != 1 || q.shape(0) != dof())
      throw py::value_error("q: " + std::to_string(dof()) + " joint values, an array of shape (" +
                            std::to_string(dof()) + ",)");
    return Eigen::Map<const Eigen::VectorXd>(q.data(), dof());
  }

  collision::RobotBoxes robot_;
};

}  // namespace

void add_collision(py::module_& module) {
  module.def(
      "distance",
      [](const DoubleArray& a, const DoubleArray& b) {
        const collision::SignedDistance r = collision::signed_distance(one_box(a, "a"), one_box(b, "b"));
        py::dict out;
        out["distance"] = r.distance;
        out["point_a"] = vector_array(r.point_a);
        out["point_b"] = vector_array(r.point_b);
        out["normal"] = vector_array(r.normal);
        return out;
      },
      py::arg("a"), py::arg("b"),
      "Signed distance between two boxes (negative: penetration depth), with the witness points and the unit "
      "normal from a to b: {'distance', 'point_a', 'point_b', 'normal'}, point_b = point_a + distance * "
      "normal.");
  module.def(
      "batch_distance", &batch_distance, py::arg("robot"), py::arg("environment"),
      py::arg("out") = py::none(),
      "Every robot box against every environment box: robot (R, 10) or (K, R, 10) at K checkpoints, "
      "environment (E, 10). Returns {'distance': (..., E), 'point_a', 'point_b', 'normal': (..., E, 3)}, "
      "the robot box as a; computed without the GIL. out: the result of an earlier call of the same shapes, "
      "filled again and returned (a planner's loop then allocates nothing).");
  module.def("_batch_distance_seconds", &batch_distance_seconds, py::arg("robot"), py::arg("environment"),
             py::arg("repeats"),
             "The C++ batch alone, seconds per call: the anchor of bench/python_bench.py.");
  module.def(
      "sphere_cover", &sphere_cover, py::arg("box"), py::arg("n"),
      "The paper's cover of a box by n spheres, (n, 4) [cx, cy, cz, r]: every point of the box is in one.");
  module.def(
      "sphere_set_distance",
      [](const DoubleArray& a, const DoubleArray& b) {
        return collision::sphere_set_distance(spheres_of(a, "a"), spheres_of(b, "b"));
      },
      py::arg("a"), py::arg("b"),
      "The smallest surface distance between two sets of spheres (N, 4) and (M, 4).");
  module.def(
      "sphere_box_distance",
      [](const DoubleArray& sphere, const DoubleArray& box) {
        if (sphere.ndim() != 1 || sphere.shape(0) != 4)
          throw py::value_error("sphere: 4 values [cx, cy, cz, r]");
        const double* v = sphere.data();
        if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]) || !std::isfinite(v[3]) ||
            v[3] < 0)
          throw py::value_error("sphere: not a finite centre and radius >= 0");
        return collision::sphere_box_distance({Eigen::Vector3d(v[0], v[1], v[2]), v[3]}, one_box(box, "box"));
      },
      py::arg("sphere"), py::arg("box"), "Signed distance from a sphere [cx, cy, cz, r] to a box.");

  py::class_<PathChecker>(
      module, "PathChecker",
      "A robot from its URDF (a box on each collision shape of the chain to tool_link) and the "
      "path check of the C++ planners.")
      .def(py::init<const std::string&, const std::string&>(), py::arg("urdf"), py::arg("tool_link"))
      .def_property_readonly("dof", &PathChecker::dof)
      .def_property_readonly("boxes", &PathChecker::boxes, "how many boxes the robot has")
      .def("place", &PathChecker::place, py::arg("q"),
           "The robot's boxes (R, 10) in the cell frame at joints q.")
      .def("blocked", &PathChecker::blocked, py::arg("control_points"), py::arg("environment"),
           py::arg("checkpoints") = 50, py::arg("margin") = 0.0, py::arg("ignore_unknown") = false,
           "Checks the cubic B-spline through control_points (M, dof) at `checkpoints` points against the "
           "environment: None when every pair keeps `margin`, else the first blocking pair: {'checkpoint', "
           "'t', 'robot_box', 'box_id', 'unknown', 'distance', 'point'}. Unknown boxes block unless "
           "ignore_unknown.");
}

}  // namespace cellmap::python
