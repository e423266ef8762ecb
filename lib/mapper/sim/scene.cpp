// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/scene.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/config/yaml_map.hpp"
#include "cellmap/urdf/urdf_model.hpp"

namespace cellmap::sim {
namespace {

std::string format_vector(const Eigen::VectorXd& v) {
  std::ostringstream out;
  out << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) out << (i ? ", " : "") << v[i];
  out << "]";
  return out.str();
}

bool all_finite(const Eigen::Isometry3d& X) {
  return X.matrix().allFinite();
}

// ---- YAML helpers: every failure names the key through YamlMap::fail.

Eigen::Vector3d positive_vec3(YamlMap& map, const std::string& key) {
  const Eigen::Vector3d v = map.vector3(key);
  if (!(v.array() > 0).all()) map.fail(key, "must be positive, got " + format_vector(v));
  return v;
}

double positive(YamlMap& map, const std::string& key) {
  const double value = map.require<double>(key);
  if (!std::isfinite(value) || !(value > 0)) {
    std::ostringstream reason;
    reason << "must be positive, got " << value;
    map.fail(key, reason.str());
  }
  return value;
}

Obstacle read_obstacle(YamlMap map) {
  Obstacle obstacle;
  obstacle.name = map.require<std::string>("name");
  if (obstacle.name.empty()) map.fail("name", "must not be empty");
  const int shapes = map.has("box") + map.has("cylinder") + map.has("sphere");
  if (shapes != 1) map.fail("box", "exactly one of box, cylinder, sphere is required");
  if (map.has("box")) {
    YamlMap box = map.child("box");
    obstacle.shape = BoxShape{positive_vec3(box, "half_extents")};
    box.expect_all_read();
  } else if (map.has("cylinder")) {
    YamlMap cylinder = map.child("cylinder");
    const double radius = positive(cylinder, "radius");
    obstacle.shape = CylinderShape{radius, positive(cylinder, "length") / 2.0};
    cylinder.expect_all_read();
  } else {
    YamlMap sphere = map.child("sphere");
    obstacle.shape = SphereShape{positive(sphere, "radius")};
    sphere.expect_all_read();
  }
  obstacle.X_CO.translation() = map.vector3("center");
  if (map.has("yaw") && map.has("rotation")) map.fail("yaw", "give either yaw or rotation, not both");
  if (map.has("yaw")) {
    const double yaw = map.number("yaw", 0.0, -2 * M_PI, 2 * M_PI);
    obstacle.X_CO.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  } else if (map.has("rotation")) {
    obstacle.X_CO.linear() = map.unit_quaternion("rotation").toRotationMatrix();
  }
  map.expect_all_read();
  return obstacle;
}

Eigen::VectorXd joint_vector(YamlMap& map, const std::string& key, int dof) {
  const std::vector<double> v = map.numbers(key, static_cast<std::size_t>(dof));
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

// `stops`: a list of joint vectors.
std::vector<Eigen::VectorXd> read_stops(YamlMap& map, int dof) {
  const YAML::Node stops = map.node("stops");
  if (!stops.IsSequence() || stops.size() == 0)
    map.fail("stops", "must be a non-empty list of joint vectors");
  std::vector<Eigen::VectorXd> q;
  for (std::size_t i = 0; i < stops.size(); ++i) {
    YAML::Node holder(YAML::NodeType::Map);
    holder["q"] = stops[i];
    YamlMap item(holder, map.key_path("stops[" + std::to_string(i) + "]"), map.source());
    q.push_back(joint_vector(item, "q", dof));
  }
  return q;
}

// `line`: {from, to, count} equidistant stops.
std::vector<Eigen::VectorXd> read_line(YamlMap line, int dof) {
  const Eigen::VectorXd from = joint_vector(line, "from", dof);
  const Eigen::VectorXd to = joint_vector(line, "to", dof);
  const long count = line.integer("count", 2, 1, 100000);
  std::vector<Eigen::VectorXd> q;
  for (long k = 0; k < count; ++k) {
    const double s = count == 1 ? 0.0 : static_cast<double>(k) / static_cast<double>(count - 1);
    q.push_back(from + s * (to - from));
  }
  line.expect_all_read();
  return q;
}

// `grid`: {from, to, counts} in serpentine order: the first joint fastest, each joint reversing direction on
// every pass of the joints above it, so consecutive stops are always neighbours and the robot never jumps
// back.
std::vector<Eigen::VectorXd> read_grid(YamlMap grid, int dof) {
  const Eigen::VectorXd from = joint_vector(grid, "from", dof);
  const Eigen::VectorXd to = joint_vector(grid, "to", dof);
  const std::vector<double> counts = grid.numbers("counts", static_cast<std::size_t>(dof));
  std::vector<long> n(counts.size());
  long total = 1;
  for (std::size_t j = 0; j < counts.size(); ++j) {
    if (counts[j] < 1 || counts[j] > 10000 || counts[j] != std::floor(counts[j])) {
      grid.fail("counts", "must be integers in [1, 10000]");
    }
    n[j] = static_cast<long>(counts[j]);
    total *= n[j];
  }
  if (total > 100000) grid.fail("counts", "more than 100000 stops");
  std::vector<Eigen::VectorXd> stops;
  for (long k = 0; k < total; ++k) {
    Eigen::VectorXd q = from;
    long span = 1;
    for (std::size_t j = 0; j < n.size(); ++j) {
      const long below = span;
      span *= n[j];
      long i = (k / below) % n[j];
      if ((k / span) % 2 == 1) i = n[j] - 1 - i;
      const double s = n[j] == 1 ? 0.0 : static_cast<double>(i) / static_cast<double>(n[j] - 1);
      const auto e = static_cast<Eigen::Index>(j);
      q[e] = from[e] + s * (to[e] - from[e]);
    }
    stops.push_back(q);
  }
  grid.expect_all_read();
  return stops;
}

// A sweep plan: exactly one of `stops` (list of joint vectors), `line` {from, to, count} or `grid` {from, to,
// counts}; plus `period`.
SweepPlan read_plan(YamlMap map, int dof) {
  SweepPlan plan;
  plan.period = map.number("period", 0.1, 1e-6, 3600.0);
  const int kinds = map.has("stops") + map.has("line") + map.has("grid");
  if (kinds != 1) map.fail("stops", "exactly one of stops, line, grid is required");
  if (map.has("stops")) {
    plan.stops = read_stops(map, dof);
  } else if (map.has("line")) {
    plan.stops = read_line(map.child("line"), dof);
  } else {
    plan.stops = read_grid(map.child("grid"), dof);
  }
  map.expect_all_read();
  return plan;
}

PinholeIntrinsics read_intrinsics(YamlMap map, SensorModel model) {
  PinholeIntrinsics k = default_intrinsics(model);
  if (map.node().size() == 0) return k;
  k.width = static_cast<int>(map.integer("width", 0, 1, 10000));
  k.height = static_cast<int>(map.integer("height", 0, 1, 10000));
  k.fx = positive(map, "fx");
  k.fy = positive(map, "fy");
  k.cx = map.number("cx", (k.width - 1) / 2.0, -1e6, 1e6);
  k.cy = map.number("cy", (k.height - 1) / 2.0, -1e6, 1e6);
  k.depth_scale = map.number("depth_scale", 0.001, 1e-6, 1.0);
  k.min_range = map.number("min_range", k.min_range, 0.0, 1000.0);
  k.max_range = map.number("max_range", k.max_range, 0.0, 1000.0);
  if (!(k.max_range > k.min_range)) map.fail("max_range", "must be greater than min_range");
  k.max_depth_jump = map.number("max_depth_jump", k.max_depth_jump, 0.0, 10.0);
  k.smoothing_radius =
      static_cast<int>(map.integer("smoothing_radius", k.smoothing_radius, 0, kMaxSmoothingRadius));
  map.expect_all_read();
  return k;
}

LineScanner read_scanner(YamlMap map) {
  LineScanner s;
  s.fov = map.number("fov", s.fov, 1e-3, 2 * M_PI);
  s.beams = static_cast<int>(map.integer("beams", s.beams, 2, 100000));
  s.min_range = map.number("min_range", s.min_range, 0.0, 1000.0);
  s.max_range = map.number("max_range", s.max_range, 0.0, 1000.0);
  if (!(s.max_range > s.min_range)) map.fail("max_range", "must be greater than min_range");
  s.range_resolution = map.number("range_resolution", s.range_resolution, 1e-6, 1.0);
  map.expect_all_read();
  return s;
}

}  // namespace

SensorMount read_mount(YamlMap& map) {
  SensorMount m;
  const YAML::Node mount = map.node("mount");
  if (mount && mount.IsScalar()) {
    const std::string where = mount.as<std::string>();
    if (where != "tool" && where != "cell")
      map.fail("mount", "must be tool, cell or a pose, got '" + where + "'");
    m.mount = where == "tool" ? Mount::kTool : Mount::kCell;
    if (!map.has("pose")) map.fail("pose", "is required with mount: " + where);
    (m.mount == Mount::kTool ? m.X_ES : m.X_CS) = map.pose("pose");
    return m;
  }
  if (map.has("pose")) map.fail("pose", "only with mount: tool or mount: cell");
  m.X_ES = map.pose("mount");
  return m;
}

namespace {

SensorSpec read_sensor(YamlMap map, int dof) {
  SensorSpec s;
  s.name = map.require<std::string>("name");
  if (s.name.empty()) map.fail("name", "must not be empty");
  try {
    s.model = sensor_model_from_string(map.require<std::string>("model"));
  } catch (const Error& e) {
    map.fail("model", e.what());
  }
  const SensorMount mount = read_mount(map);
  s.mount = mount.mount;
  s.X_ES = mount.X_ES;
  s.X_CS = mount.X_CS;
  if (s.is_camera()) {
    s.intrinsics = read_intrinsics(map.child("intrinsics"), s.model);
    if (map.has("scanner")) map.fail("scanner", "only for a line scanner (model os32c)");
  } else {
    s.scanner = read_scanner(map.child("scanner"));
    if (map.has("intrinsics")) map.fail("intrinsics", "only for cameras (kinect_v2, realsense_d435)");
  }
  s.seed = static_cast<std::uint64_t>(map.integer("seed", 1, 0, 1L << 62));
  if (map.has("sweep")) s.sweep = read_plan(map.child("sweep"), dof);
  map.expect_all_read();
  return s;
}

Waypoint read_waypoint(YamlMap map, int dof) {
  Waypoint w;
  w.time = map.number("time", 0.0, 0.0, 1e6);
  w.q = joint_vector(map, "q", dof);
  w.pick = map.get<std::string>("pick", "");
  w.place = map.get<bool>("place", false);
  map.expect_all_read();
  return w;
}

Walker read_walker(YamlMap map) {
  Walker w;
  w.name = map.require<std::string>("name");
  w.radius = positive(map, "radius");
  w.height = positive(map, "height");
  w.floor = map.number("floor", 0.0, -1e3, 1e3);
  const YAML::Node path = map.node("path");
  if (!path || !path.IsSequence()) map.fail("path", "must be a list of {time, at: [x, y]}");
  for (std::size_t i = 0; i < path.size(); ++i) {
    YamlMap point(path[i], map.key_path("path[" + std::to_string(i) + "]"), map.source());
    const std::vector<double> at = point.numbers("at", 2);
    w.path.push_back({point.number("time", 0.0, 0.0, 1e6), Eigen::Vector2d(at[0], at[1])});
    point.expect_all_read();
  }
  map.expect_all_read();
  return w;
}

template <typename Read>
auto read_list(YamlMap& root, const std::string& key, Read read) {
  const YAML::Node list = root.node(key);
  if (!list || !list.IsSequence()) root.fail(key, "must be a list");
  std::vector<decltype(read(std::declval<YamlMap>()))> items;
  for (std::size_t i = 0; i < list.size(); ++i) {
    items.push_back(
        read(YamlMap(list[i], root.key_path(key + "[" + std::to_string(i) + "]"), root.source())));
  }
  return items;
}

void check_shape(const Shape& shape, const std::string& what) {
  bool ok = false;
  if (const auto* box = std::get_if<BoxShape>(&shape)) ok = (box->half_extents.array() > 0).all();
  if (const auto* cyl = std::get_if<CylinderShape>(&shape)) ok = cyl->radius > 0 && cyl->half_length > 0;
  if (const auto* sphere = std::get_if<SphereShape>(&shape)) ok = sphere->radius > 0;
  if (!ok) throw Error(what + ": sizes must be positive and finite");
}

GantryParts::Part read_part(YamlMap& gantry, const std::string& key, const GantryParts::Part& fallback) {
  if (!gantry.has(key)) return fallback;
  YamlMap map = gantry.child(key);
  GantryParts::Part part{map.vector3("center"), positive_vec3(map, "half_extents")};
  map.expect_all_read();
  return part;
}

}  // namespace

Robot read_robot(YamlMap map, const std::string& base_dir) {
  if (map.has("gantry") == map.has("urdf")) map.fail("gantry", "exactly one of gantry, urdf is required");
  if (map.has("gantry")) {
    YamlMap gantry = map.child("gantry");
    const Eigen::Vector3d lower = gantry.vector3("lower");
    const Eigen::Vector3d upper = gantry.vector3("upper");
    if (!(lower.array() <= upper.array()).all()) gantry.fail("upper", "must be >= lower on every axis");
    const Eigen::Isometry3d X_CE_zero = gantry.pose("tool_at_zero");
    const GantryParts fitting = GantryParts::fitting(lower, upper, X_CE_zero);
    GantryParts parts;
    parts.bridge = read_part(gantry, "bridge", fitting.bridge);
    parts.carriage = read_part(gantry, "carriage", fitting.carriage);
    parts.ram = read_part(gantry, "ram", fitting.ram);
    gantry.expect_all_read();
    map.expect_all_read();
    return Robot::gantry(lower, upper, X_CE_zero, parts);
  }
  YamlMap urdf = map.child("urdf");
  std::filesystem::path file = urdf.require<std::string>("file");
  if (file.is_relative()) file = std::filesystem::path(base_dir) / file;
  const std::string tool_link = urdf.require<std::string>("tool_link");
  const Eigen::Isometry3d X_C_root = urdf.pose("base");
  std::vector<std::string> package_paths;
  if (urdf.has("package_paths")) {
    package_paths = urdf.require<std::vector<std::string>>("package_paths");
    for (std::string& path : package_paths) {
      if (std::filesystem::path(path).is_relative()) path = (std::filesystem::path(base_dir) / path).string();
    }
  }
  urdf.expect_all_read();
  map.expect_all_read();
  try {
    return UrdfModel::load(file.string()).robot(tool_link, X_C_root, package_paths);
  } catch (const Error& e) {
    map.fail("urdf", e.what());
  }
}

double Obstacle::volume() const {
  if (const auto* box = std::get_if<BoxShape>(&shape)) return 8.0 * box->half_extents.prod();
  if (const auto* cyl = std::get_if<CylinderShape>(&shape)) {
    return M_PI * cyl->radius * cyl->radius * 2.0 * cyl->half_length;
  }
  const double r = std::get<SphereShape>(shape).radius;
  return 4.0 / 3.0 * M_PI * r * r * r;
}

double Obstacle::surface_area() const {
  if (const auto* box = std::get_if<BoxShape>(&shape)) {
    const Eigen::Vector3d& h = box->half_extents;
    return 8.0 * (h.x() * h.y() + h.y() * h.z() + h.x() * h.z());
  }
  if (const auto* cyl = std::get_if<CylinderShape>(&shape)) {
    return 2.0 * M_PI * cyl->radius * (cyl->radius + 2.0 * cyl->half_length);
  }
  const double r = std::get<SphereShape>(shape).radius;
  return 4.0 * M_PI * r * r;
}

double Obstacle::signed_distance(const Eigen::Vector3d& p_C) const {
  const Eigen::Vector3d p_O = X_CO.inverse() * p_C;
  if (const auto* box = std::get_if<BoxShape>(&shape)) {
    const Eigen::Vector3d d = p_O.cwiseAbs() - box->half_extents;
    return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
  }
  if (const auto* cyl = std::get_if<CylinderShape>(&shape)) {
    const Eigen::Vector2d d(p_O.head<2>().norm() - cyl->radius, std::abs(p_O.z()) - cyl->half_length);
    return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
  }
  return p_O.norm() - std::get<SphereShape>(shape).radius;
}

double Obstacle::bounding_radius() const {
  if (const auto* box = std::get_if<BoxShape>(&shape)) return box->half_extents.norm();
  if (const auto* cyl = std::get_if<CylinderShape>(&shape)) return std::hypot(cyl->radius, cyl->half_length);
  return std::get<SphereShape>(shape).radius;
}

std::vector<Eigen::Vector3d> Obstacle::sample_surface(double spacing) const {
  if (!(spacing > 0)) throw Error("sample_surface: spacing must be positive");
  std::vector<Eigen::Vector3d> p_O;
  auto cells = [&](double length) { return std::max(1, static_cast<int>(std::ceil(length / spacing))); };
  if (const auto* box = std::get_if<BoxShape>(&shape)) {
    const Eigen::Vector3d& h = box->half_extents;
    for (int axis = 0; axis < 3; ++axis) {
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      const int na = cells(2 * h[a]), nb = cells(2 * h[b]);
      for (int side = -1; side <= 1; side += 2) {
        for (int i = 0; i < na; ++i) {
          for (int j = 0; j < nb; ++j) {
            Eigen::Vector3d p;
            p[axis] = side * h[axis];
            p[a] = -h[a] + (i + 0.5) * 2 * h[a] / na;
            p[b] = -h[b] + (j + 0.5) * 2 * h[b] / nb;
            p_O.push_back(p);
          }
        }
      }
    }
  } else if (const auto* cyl = std::get_if<CylinderShape>(&shape)) {
    const double r = cyl->radius, hl = cyl->half_length;
    const int around = cells(2 * M_PI * r), along = cells(2 * hl);
    for (int i = 0; i < around; ++i) {
      const double phi = 2 * M_PI * (i + 0.5) / around;
      for (int j = 0; j < along; ++j) {
        p_O.emplace_back(r * std::cos(phi), r * std::sin(phi), -hl + (j + 0.5) * 2 * hl / along);
      }
    }
    const int rings = cells(r);
    for (int side = -1; side <= 1; side += 2) {
      for (int ring = 0; ring < rings; ++ring) {
        const double rho = (ring + 0.5) * r / rings;
        const int n = cells(2 * M_PI * rho);
        for (int i = 0; i < n; ++i) {
          const double phi = 2 * M_PI * (i + 0.5) / n;
          p_O.emplace_back(rho * std::cos(phi), rho * std::sin(phi), side * hl);
        }
      }
    }
  } else {
    // Fibonacci lattice: near-uniform points, one per spacing² of area.
    const double r = std::get<SphereShape>(shape).radius;
    const int n = std::max(4, static_cast<int>(std::ceil(4 * M_PI * r * r / (spacing * spacing))));
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
      const double z = 1.0 - (i + 0.5) * 2.0 / n;
      const double rho = std::sqrt(1.0 - z * z);
      p_O.emplace_back(r * rho * std::cos(golden * i), r * rho * std::sin(golden * i), r * z);
    }
  }
  std::vector<Eigen::Vector3d> p_C;
  p_C.reserve(p_O.size());
  for (const Eigen::Vector3d& p : p_O) p_C.push_back(X_CO * p);
  return p_C;
}

std::string to_string(SensorModel model) {
  switch (model) {
    case SensorModel::kKinectV2:
      return "kinect_v2";
    case SensorModel::kRealsenseD435:
      return "realsense_d435";
    case SensorModel::kOs32c:
      return "os32c";
  }
  return "unknown";
}

SensorModel sensor_model_from_string(const std::string& name) {
  for (SensorModel m : {SensorModel::kKinectV2, SensorModel::kRealsenseD435, SensorModel::kOs32c}) {
    if (to_string(m) == name) return m;
  }
  throw Error("unknown sensor model '" + single_line(name) + "' (known: kinect_v2, realsense_d435, os32c)");
}

void LineScanner::validate() const {
  if (!(fov > 0 && fov <= 2 * M_PI)) throw Error("scanner: fov must be in (0, 2π]");
  if (beams < 2) throw Error("scanner: beams must be >= 2");
  if (!(min_range >= 0 && max_range > min_range)) throw Error("scanner: need 0 <= min_range < max_range");
  if (!(range_resolution > 0)) throw Error("scanner: range_resolution must be positive");
}

Scene without_depth_filter(Scene scene) {
  for (SensorSpec& sensor : scene.sensors) {
    sensor.intrinsics.max_depth_jump = 0;
    sensor.intrinsics.smoothing_radius = 0;
  }
  return scene;
}

FieldOfView LineScanner::field_of_view() const {
  constexpr double kMaxStep = M_PI / 6;
  const int steps = std::max(1, static_cast<int>(std::ceil(fov / kMaxStep)));
  FieldOfView out{{}, false, max_range};
  for (int i = 0; i <= steps; ++i) {
    const double angle = -fov / 2 + fov * i / steps;  // as the beams: about +z from +x
    out.outline_S.emplace_back(std::cos(angle), std::sin(angle), 0.0);
  }
  return out;
}

PinholeIntrinsics default_intrinsics(SensorModel model) {
  PinholeIntrinsics k;
  k.depth_scale = 0.001;
  switch (model) {
    case SensorModel::kKinectV2:
      // 512×424 time-of-flight depth, 70.6° × 60° field of view, 0.5–4.5 m.
      k.width = 512, k.height = 424, k.fx = 365.0, k.fy = 365.0, k.cx = 255.5, k.cy = 211.5;
      k.min_range = 0.5, k.max_range = 4.5;
      k.max_depth_jump = kDefaultMaxDepthJump;
      return k;
    case SensorModel::kRealsenseD435:
      // 640×480 stereo depth (87° × 58° native), 0.2–10 m.
      k.width = 640, k.height = 480, k.fx = 383.0, k.fy = 383.0, k.cx = 319.5, k.cy = 239.5;
      k.min_range = 0.2, k.max_range = 10.0;
      k.max_depth_jump = kStereoMaxDepthJump;
      k.smoothing_radius = kStereoSmoothingRadius;
      return k;
    case SensorModel::kOs32c:
      break;
  }
  throw Error("sensor model " + to_string(model) + " is not a camera");
}

const SweepPlan& Scene::plan_for(const SensorSpec& sensor) const {
  return sensor.sweep ? *sensor.sweep : sweep;
}

int Scene::find_obstacle(const std::string& name) const {
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    if (obstacles[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int Scene::find_sensor(const std::string& name) const {
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    if (sensors[i].name == name) return static_cast<int>(i);
  }
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    if (to_string(sensors[i].model) == name) return static_cast<int>(i);
  }
  return -1;
}

Eigen::Isometry3d Scene::sensor_pose(int index, const Eigen::VectorXd& q) const {
  if (index < 0 || index >= static_cast<int>(sensors.size())) {
    throw Error("sensor index " + std::to_string(index) + " out of range");
  }
  const SensorSpec& sensor = sensors[static_cast<std::size_t>(index)];
  if (sensor.mount == Mount::kCell) return sensor.X_CS;
  return robot.tool_pose(q) * sensor.X_ES;
}

namespace {

void validate_obstacles(const std::vector<Obstacle>& obstacles) {
  std::set<std::string> names;
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const Obstacle& o = obstacles[i];
    const std::string what = "obstacles[" + std::to_string(i) + "] '" + o.name + "'";
    if (o.name.empty()) throw Error("obstacles[" + std::to_string(i) + "].name: must not be empty");
    if (!names.insert(o.name).second) throw Error(what + ": name used twice");
    check_shape(o.shape, what);
    if (!all_finite(o.X_CO)) throw Error(what + ": pose must be finite");
  }
}

// `plan` (the YAML key `key`) has stops, a positive period and every stop within the robot's joint limits.
void check_plan(const SweepPlan& plan, const std::string& key, const Robot& robot) {
  if (plan.stops.empty()) throw Error(key + ": no stops");
  if (!(plan.period > 0)) throw Error(key + ".period: must be positive");
  for (std::size_t k = 0; k < plan.stops.size(); ++k) {
    if (!robot.within_limits(plan.stops[k])) {
      throw Error(key + ": stop " + std::to_string(k) + " q = " + format_vector(plan.stops[k]) +
                  " is outside the robot's joint limits or has the wrong size (dof " +
                  std::to_string(robot.dof()) + ")");
    }
  }
}

// Sensor i: its name (not in `names` yet), pose, intrinsics or scanner, its own plan and that it stays inside
// the cell at every stop of its plan.
void validate_sensor(const Scene& scene, std::size_t i, std::set<std::string>& names) {
  const SensorSpec& s = scene.sensors[i];
  const std::string key = "sensors[" + std::to_string(i) + "]";
  if (s.name.empty()) throw Error(key + ".name: must not be empty");
  if (!names.insert(s.name).second) throw Error(key + ".name: '" + s.name + "' used twice");
  if (!all_finite(s.X_ES) || !all_finite(s.X_CS)) throw Error(key + ".mount: pose must be finite");
  try {
    if (s.is_camera()) {
      s.intrinsics.validate();
    } else {
      s.scanner.validate();
    }
  } catch (const Error& e) {
    throw Error(key + ": " + e.what());
  }
  const SweepPlan& plan = scene.plan_for(s);
  const std::string plan_key = s.sweep ? key + ".sweep" : std::string("sweep");
  if (s.sweep) check_plan(*s.sweep, plan_key, scene.robot);
  for (std::size_t k = 0; k < plan.stops.size(); ++k) {
    const Eigen::Vector3d p_CS = scene.sensor_pose(static_cast<int>(i), plan.stops[k]).translation();
    if (!scene.cell.contains(p_CS)) {
      throw Error(key + ".mount: sensor '" + s.name + "' is outside the cell at " + plan_key + " stop " +
                  std::to_string(k) + " (sensor at " + format_vector(p_CS) + ", cell " +
                  format_vector(scene.cell.min) + " to " + format_vector(scene.cell.max) + ")");
    }
  }
}

void validate_motion(const Scene& scene) {
  scene.motion->validate(scene.robot);
  for (const Waypoint& w : scene.motion->waypoints) {
    const int picked = scene.find_obstacle(w.pick);
    if (!w.pick.empty() && (picked < 0 || !std::holds_alternative<BoxShape>(scene.obstacles[picked].shape))) {
      throw Error("motion: pick '" + w.pick + "': no box obstacle of that name");
    }
  }
}

}  // namespace

void Scene::validate() const {
  if (!cell.min.allFinite() || !cell.max.allFinite() || !(cell.min.array() < cell.max.array()).all()) {
    throw Error("cell: min must be below max on every axis");
  }
  validate_obstacles(obstacles);
  check_plan(sweep, "sweep", robot);
  std::set<std::string> sensor_names;
  for (std::size_t i = 0; i < sensors.size(); ++i) validate_sensor(*this, i, sensor_names);
  if (sensors.empty()) throw Error("sensors: at least one sensor is required");
  if (motion) validate_motion(*this);
  for (const Walker& walker : walkers) walker.validate();
}

Scene parse_scene(const std::string& yaml, const std::string& source, const std::string& base_dir) {
  YamlMap root = YamlMap::parse(yaml, source);
  YamlMap cell_map = root.child("cell");
  Region cell{cell_map.vector3("min"), cell_map.vector3("max")};
  if (!(cell.min.array() < cell.max.array()).all()) cell_map.fail("max", "must be above min on every axis");
  cell_map.expect_all_read();

  std::vector<Obstacle> obstacles;
  if (root.has("obstacles")) obstacles = read_list(root, "obstacles", read_obstacle);
  Robot robot = read_robot(root.child("robot"), base_dir);
  const int dof = robot.dof();
  std::vector<SensorSpec> sensors =
      read_list(root, "sensors", [dof](YamlMap map) { return read_sensor(std::move(map), dof); });
  SweepPlan plan = read_plan(root.child("sweep"), dof);
  std::optional<Motion> motion;
  if (root.has("motion")) {
    YamlMap map = root.child("motion");
    motion.emplace();
    motion->loop = map.get<bool>("loop", true);
    motion->controller_rate = map.number("controller_rate", 250.0, 1.0, 10000.0);
    motion->joint_stamp_delay = map.number("joint_stamp_delay", 0.0, -1.0, 1.0);
    motion->waypoints =
        read_list(map, "waypoints", [dof](YamlMap item) { return read_waypoint(std::move(item), dof); });
    map.expect_all_read();
  }
  std::vector<Walker> walkers;
  if (root.has("walkers")) walkers = read_list(root, "walkers", read_walker);
  std::optional<Region> workspace;
  if (root.has("workspace")) {
    YamlMap map = root.child("workspace");
    workspace = Region{map.vector3("lower"), map.vector3("upper")};
    if (!(workspace->min.array() < workspace->max.array()).all())
      map.fail("upper", "must be above lower on every axis");
    map.expect_all_read();
  }
  root.expect_all_read();

  Scene scene{cell,
              std::move(obstacles),
              std::move(robot),
              std::move(sensors),
              std::move(plan),
              std::move(motion),
              std::move(walkers),
              workspace};
  try {
    scene.validate();
  } catch (const Error& e) {
    throw Error(source + ": " + e.what());
  }
  return scene;
}

Scene load_scene(const std::string& file) {
  return parse_scene(read_file(file), file, std::filesystem::path(file).parent_path().string());
}

}  // namespace cellmap::sim
