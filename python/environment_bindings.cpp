// SPDX-License-Identifier: Apache-2.0
// cellmap.Environment, cellmap.EnvironmentDelta, cellmap.EnvironmentSubscriber (the C++ planner client,
// wrapped: the same snapshot, delta and resync rules) and the boxes JSON files.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>

#include "bindings.hpp"
#include "cellmap/boxes/box.hpp"
#include "cellmap/security/credentials.hpp"
#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/environment_subscriber.hpp"

namespace cellmap::python {
namespace {

using U64Array = py::array_t<std::uint64_t>;

U64Array ids_of(const std::vector<Box>& boxes) {
  U64Array ids(static_cast<py::ssize_t>(boxes.size()));
  auto out = ids.mutable_unchecked<1>();
  for (std::size_t i = 0; i < boxes.size(); ++i) out(static_cast<py::ssize_t>(i)) = boxes[i].id;
  return ids;
}

U64Array u64_array(const std::vector<std::uint64_t>& values) {
  U64Array array(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), array.mutable_data());
  return array;
}

// (N, 3) or (N, 4) of one field of each box.
template <int Columns, class Field>
DoubleArray column_array(const std::vector<Box>& boxes, Field field) {
  DoubleArray out = new_array({static_cast<py::ssize_t>(boxes.size()), Columns});
  auto view = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const auto values = field(boxes[i]);
    for (int c = 0; c < Columns; ++c) view(static_cast<py::ssize_t>(i), c) = values[c];
  }
  return out;
}

void add_box_arrays(py::class_<Environment>& environment) {
  environment
      .def_property_readonly(
          "ids", [](const Environment& e) { return ids_of(e.boxes()); }, "box ids, (N,) uint64")
      .def_property_readonly(
          "centers",
          [](const Environment& e) {
            return column_array<3>(e.boxes(), [](const Box& b) {
              return std::array{b.center.x(), b.center.y(), b.center.z()};
            });
          },
          "box centres p_CB, (N, 3) metres")
      .def_property_readonly(
          "half_extents",
          [](const Environment& e) {
            return column_array<3>(e.boxes(), [](const Box& b) {
              return std::array{b.half_extents.x(), b.half_extents.y(), b.half_extents.z()};
            });
          },
          "half extents along each box's own axes, (N, 3) metres")
      .def_property_readonly(
          "rotations",
          [](const Environment& e) {
            return column_array<4>(e.boxes(), [](const Box& b) {
              return std::array{b.rotation.w(), b.rotation.x(), b.rotation.y(), b.rotation.z()};
            });
          },
          "rotations R_CB as unit quaternions [w, x, y, z], (N, 4)")
      .def_property_readonly(
          "unknown",
          [](const Environment& e) {
            py::array_t<bool> out(static_cast<py::ssize_t>(e.boxes().size()));
            for (std::size_t i = 0; i < e.boxes().size(); ++i)
              out.mutable_data()[i] = e.boxes()[i].space == BoxSpace::kUnknown;
            return out;
          },
          "True for a box of space no sensor has observed, (N,) bool")
      .def_property_readonly(
          "boxes", [](const Environment& e) { return boxes_array(e.boxes()); },
          "the boxes as (N, 10) [cx, cy, cz, hx, hy, hz, qw, qx, qy, qz], for the collision functions");
}

// An optional timeout in seconds: None waits for ever.
std::chrono::nanoseconds timeout_of(const std::optional<double>& seconds) {
  if (!seconds) return std::chrono::hours(24 * 365);
  if (!std::isfinite(*seconds) || *seconds < 0)
    throw py::value_error("timeout: must be a number of seconds >= 0");
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(*seconds));
}

// One participant and its subscriber; Python owns it.
class Subscriber final {
 public:
  Subscriber(int domain, const std::string& cell, const std::optional<std::string>& security,
             const std::string& role, std::optional<py::function> on_change) {
    if (domain < 0 || domain > 232)
      throw py::value_error("domain: " + std::to_string(domain) + " is not in 0-232");
    if (cell.empty()) throw py::value_error("cell: must not be empty");
    std::optional<security::Setting> setting;
    if (security) setting = security::Setting{*security, security::parse_role(role)};
    participant_ = std::make_unique<dds::Participant>(static_cast<std::uint32_t>(domain), setting);
    transport::EnvironmentSubscriber::Callback callback;
    if (on_change) {
      on_change_ = std::move(*on_change);
      callback = [this](const Environment& e, const EnvironmentDelta& d) { call_back(on_change_, e, d); };
    }
    subscriber_ =
        std::make_unique<transport::EnvironmentSubscriber>(*participant_, cell, std::move(callback));
  }
  // Closing joins the receiving thread, which may wait for the GIL in a callback: never with the GIL held.
  ~Subscriber() {
    if (subscriber_) {
      py::gil_scoped_release release;
      close();
    }
  }

  void close() {
    subscriber_.reset();
    participant_.reset();
  }

  [[nodiscard]] std::optional<Environment> environment() const { return live().environment(); }

  std::optional<Environment> wait(std::optional<double> timeout, std::optional<std::uint64_t> version) const {
    const transport::EnvironmentSubscriber& subscriber = live();
    const std::uint64_t wanted = version.value_or(
        subscriber.environment() ? subscriber.environment()->version() + 1 : std::uint64_t{1});
    bool reached = false;
    {
      py::gil_scoped_release release;
      reached = subscriber.wait_for_version(wanted, timeout_of(timeout));
    }
    if (!reached) return std::nullopt;
    return subscriber.environment();
  }

  [[nodiscard]] py::dict stats() const {
    const transport::TrackerStats s = live().stats();
    py::dict d;
    d["deltas_applied"] = s.deltas_applied;
    d["snapshots_applied"] = s.snapshots_applied;
    d["gaps"] = s.gaps;
    d["rejected"] = s.rejected;
    d["other_cells"] = s.other_cells;
    d["went_back"] = s.went_back;
    d["implausible"] = s.implausible;
    return d;
  }

  [[nodiscard]] std::string last_error() const { return live().last_error(); }

 private:
  const transport::EnvironmentSubscriber& live() const {
    if (!subscriber_) throw py::value_error("EnvironmentSubscriber: closed");
    return *subscriber_;
  }

  // From the receiving thread: a callback that raises is reported (sys.unraisablehook) and the next change
  // is called back as usual.
  static void call_back(const py::object& function, const Environment& environment,
                        const EnvironmentDelta& delta) {
    py::gil_scoped_acquire acquire;
    try {
      function(environment, delta);
    } catch (py::error_already_set& e) {
      e.discard_as_unraisable("cellmap.EnvironmentSubscriber on_change");
    }
  }

  // Python's callable, released (with the GIL) only after the receiving thread has stopped.
  py::object on_change_;
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<transport::EnvironmentSubscriber> subscriber_;
};

Environment environment_from(const std::string& cell, std::uint64_t version, std::int64_t stamp_ns,
                             const DoubleArray& boxes, const std::optional<py::array_t<std::uint64_t>>& ids) {
  const std::vector<collision::Obb> obbs = obbs_of(boxes, "boxes");
  if (ids && static_cast<std::size_t>(ids->size()) != obbs.size())
    throw py::value_error("ids: " + std::to_string(ids->size()) + " ids for " + std::to_string(obbs.size()) +
                          " boxes");
  std::vector<Box> out;
  for (std::size_t i = 0; i < obbs.size(); ++i) {
    Box box = collision::to_box(obbs[i]);
    box.id = ids ? ids->data()[i] : i + 1;
    out.push_back(box);
  }
  return Environment(cell, version, stamp_ns, std::move(out));
}

}  // namespace

DoubleArray boxes_array(const std::vector<Box>& boxes) {
  DoubleArray out = new_array({static_cast<py::ssize_t>(boxes.size()), 10});
  double* v = out.mutable_data();
  for (const Box& b : boxes) {
    const double values[10] = {b.center.x(),       b.center.y(),       b.center.z(),   b.half_extents.x(),
                               b.half_extents.y(), b.half_extents.z(), b.rotation.w(), b.rotation.x(),
                               b.rotation.y(),     b.rotation.z()};
    v = std::copy(values, values + 10, v);
  }
  return out;
}

void add_environment(py::module_& module) {
  py::class_<Environment> environment(module, "Environment",
                                      "One version of a cell's environment: its boxes in the cell frame.");
  environment
      .def(py::init(&environment_from), py::arg("cell"), py::arg("version"), py::arg("stamp_ns"),
           py::arg("boxes"), py::arg("ids") = py::none(),
           "An environment of boxes (N, 10); ids default to 1..N. Raises ValueError for bad boxes or "
           "repeated ids.")
      .def_property_readonly("cell", &Environment::cell)
      .def_property_readonly("version", &Environment::version, "strictly increasing per cell; 0: nothing yet")
      .def_property_readonly("stamp_ns", &Environment::stamp_ns,
                             "when the version was made, ns since the Unix epoch")
      .def("__len__", [](const Environment& e) { return e.boxes().size(); })
      .def("__eq__", [](const Environment& a, const Environment& b) { return a == b; })
      .def("__repr__", [](const Environment& e) {
        return "<cellmap.Environment cell '" + e.cell() + "' version " + std::to_string(e.version()) + ", " +
               std::to_string(e.boxes().size()) + " boxes>";
      });
  add_box_arrays(environment);

  py::class_<EnvironmentDelta>(module, "EnvironmentDelta", "What changed from one version to the next.")
      .def_readonly("cell", &EnvironmentDelta::cell)
      .def_readonly("from_version", &EnvironmentDelta::from_version)
      .def_readonly("to_version", &EnvironmentDelta::to_version)
      .def_readonly("stamp_ns", &EnvironmentDelta::stamp_ns)
      .def_property_readonly(
          "added", [](const EnvironmentDelta& d) { return ids_of(d.added); }, "ids of added boxes")
      .def_property_readonly(
          "modified", [](const EnvironmentDelta& d) { return ids_of(d.modified); }, "ids of modified boxes")
      .def_property_readonly(
          "removed", [](const EnvironmentDelta& d) { return u64_array(d.removed); }, "ids of removed boxes")
      .def("__repr__", [](const EnvironmentDelta& d) {
        return "<cellmap.EnvironmentDelta " + std::to_string(d.from_version) + " -> " +
               std::to_string(d.to_version) + ": +" + std::to_string(d.added.size()) + " ~" +
               std::to_string(d.modified.size()) + " -" + std::to_string(d.removed.size()) + ">";
      });

  py::class_<Subscriber>(
      module, "EnvironmentSubscriber",
      "Follows one cell over DDS: the C++ planner client (snapshot at start, deltas in order, "
      "resync after a gap). A context manager; close() stops it.")
      .def(py::init<int, const std::string&, const std::optional<std::string>&, const std::string&,
                    std::optional<py::function>>(),
           py::arg("domain") = 0, py::arg("cell") = "cell", py::arg("security") = py::none(),
           py::arg("role") = "planner", py::arg("on_change") = py::none(),
           "domain: DDS domain 0-232; security: the credentials folder (cellmap security init/export), None: "
           "off; "
           "on_change(environment, delta): called on every change from the receiving thread")
      .def("environment", &Subscriber::environment, "The local copy, or None before the first snapshot.")
      .def("wait", &Subscriber::wait, py::arg("timeout") = py::none(), py::arg("version") = py::none(),
           "Waits until the copy reaches `version` (default: newer than now) and returns it, or None after "
           "`timeout` seconds (None: no limit).")
      .def("stats", &Subscriber::stats, "The client's counters: deltas_applied, snapshots_applied, gaps, ...")
      .def("last_error", &Subscriber::last_error, "The last problem of the receiving thread, or ''.")
      .def(
          "close",
          [](Subscriber& s) {
            py::gil_scoped_release release;
            s.close();
          },
          "Stops receiving; the subscriber cannot be used after.")
      .def("__enter__", [](Subscriber& s) -> Subscriber& { return s; })
      .def("__exit__", [](Subscriber& s, const py::args&) {
        py::gil_scoped_release release;
        s.close();
      });

  module.def(
      "read_boxes",
      [](const std::string& path) {
        BoxSet set = read_box_file(path);
        return Environment(set.frame, set.version, 0, std::move(set.boxes));
      },
      py::arg("path"),
      "A boxes JSON file (docs/boxes-json.md) as an Environment whose cell is the file's frame.");
  module.def(
      "write_boxes",
      [](const std::string& path, const Environment& environment) {
        write_box_file(path, BoxSet{environment.version(), environment.cell(), environment.boxes()});
      },
      py::arg("path"), py::arg("environment"),
      "Writes the environment's boxes as a boxes JSON file (atomically).");
}

}  // namespace cellmap::python
