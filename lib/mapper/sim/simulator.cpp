// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cellmap/common/error.hpp"
#include "cellmap/common/parallel.hpp"

namespace cellmap::sim {
namespace {

constexpr int kTile = 16;  // pixels per side of the tiles that share one candidate list

Scene validated(Scene scene) {
  scene.validate();
  return scene;
}

// First multiple k of `period` with k·period >= t.
long first_tick(double t, double period) {
  return static_cast<long>(std::ceil(t / period - 1e-9));
}

// Unnormalised ray of pixel (u, v) in S; its z component is 1, so depth z = t / |ray|.
Eigen::Vector3d pixel_ray_S(const PinholeIntrinsics& k, double u, double v) {
  return Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
}

// The obstacles that rays of the tile of pixels [u0, u1] × [v0, v1] may hit: those in the cone around its
// four corner rays, which holds every ray of the tile (the tile is convex on the image plane).
std::vector<SceneCaster::Candidate> tile_candidates(const SceneCaster& caster, const PinholeIntrinsics& k,
                                                    const Eigen::Isometry3d& X_CS, int u0, int v0, int u1,
                                                    int v1) {
  const Eigen::Vector3d corners[4] = {
      pixel_ray_S(k, u0, v0).normalized(), pixel_ray_S(k, u1, v0).normalized(),
      pixel_ray_S(k, u0, v1).normalized(), pixel_ray_S(k, u1, v1).normalized()};
  const Eigen::Vector3d axis_S = (corners[0] + corners[1] + corners[2] + corners[3]).normalized();
  double half_angle = 0;
  for (const Eigen::Vector3d& c : corners) {
    half_angle = std::max(half_angle, std::acos(std::clamp(axis_S.dot(c), -1.0, 1.0)));
  }
  const Eigen::Matrix3d R_CS = X_CS.linear();
  return caster.candidates(X_CS.translation(), R_CS * axis_S, half_angle + 1e-9);
}

// The exact depth of every pixel (0: nothing within the camera's range and the cell) and the obstacle hit,
// cast tile by tile on `threads` threads.
SimFrame cast_pixels(const PinholeIntrinsics& k, const Eigen::Isometry3d& X_CS, const Region& cell,
                     const SceneCaster& caster, int threads) {
  const int width = k.width, height = k.height;
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const Eigen::Matrix3d R_CS = X_CS.linear();
  const Eigen::Vector3d p_CS = X_CS.translation();
  SimFrame out;
  out.exact.assign(pixels, 0.0);
  out.hit.assign(pixels, RayHit::kNothing);
  const int tiles_u = (width + kTile - 1) / kTile, tiles_v = (height + kTile - 1) / kTile;
  parallel_for(tiles_u * tiles_v, threads, [&](int tile) {
    const int u0 = (tile % tiles_u) * kTile, v0 = (tile / tiles_u) * kTile;
    const int u1 = std::min(width, u0 + kTile) - 1, v1 = std::min(height, v0 + kTile) - 1;
    const std::vector<SceneCaster::Candidate> candidates = tile_candidates(caster, k, X_CS, u0, v0, u1, v1);
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        const Eigen::Vector3d r_S = pixel_ray_S(k, u, v);
        const double length = r_S.norm();
        const Eigen::Vector3d d_C = R_CS * (r_S / length);
        const double t_max = std::min(exit_distance(cell, p_CS, d_C), k.max_range * length);
        const RayHit hit = caster.cast(p_CS, d_C, t_max, &candidates);
        if (hit.obstacle == RayHit::kNothing) continue;
        const double z = hit.t / length;
        if (z < k.min_range || z > k.max_range) continue;
        const std::size_t p = static_cast<std::size_t>(v) * width + u;
        out.exact[p] = z;
        out.hit[p] = hit.obstacle;
      }
    }
  });
  return out;
}

// The depth image of depths `z` as the camera quantizes them (raw units of depth_scale, 0 = no return),
// without what lies outside the cell.
DepthImage quantized(const std::vector<double>& z, const PinholeIntrinsics& k, const Eigen::Isometry3d& X_CS,
                     const Region& cell) {
  DepthImage image;
  image.intrinsics = k;
  image.depth.assign(z.size(), 0);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * k.width + u;
      if (z[p] <= 0) continue;
      const double raw = std::round(z[p] / k.depth_scale);
      const double quantized_z = raw * k.depth_scale;
      if (raw < 1 || raw > 65535 || quantized_z < k.min_range || quantized_z > k.max_range) continue;
      if (!cell.contains(X_CS * (pixel_ray_S(k, u, v) * quantized_z))) continue;
      image.depth[p] = static_cast<std::uint16_t>(raw);
    }
  }
  return image;
}

}  // namespace

Simulator::Simulator(Scene scene, SimOptions options)
    : scene_(validated(std::move(scene))),
      options_(options),
      caster_(scene_.obstacles),
      robot_solids_(scene_.robot) {
  if (!scene_.motion) return;
  const std::vector<Waypoint>& path = scene_.motion->waypoints;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (path[i].pick.empty()) continue;
    const Obstacle& box = scene_.obstacles[static_cast<std::size_t>(scene_.find_obstacle(path[i].pick))];
    Carry carry{box.name, path[i].time, std::numeric_limits<double>::infinity(), {}, box};
    const Eigen::Isometry3d X_CE = scene_.robot.tool_pose(path[i].q);
    carry.payload.X_EB = X_CE.inverse() * box.X_CO;
    carry.payload.half_extents = std::get<BoxShape>(box.shape).half_extents;
    for (std::size_t j = i + 1; j < path.size(); ++j) {
      if (!path[j].place) continue;
      carry.place_time = path[j].time;
      carry.placed.X_CO = scene_.robot.tool_pose(path[j].q) * carry.payload.X_EB;
      break;
    }
    carries_.push_back(carry);
  }
}

CellState Simulator::state_at(double t) const {
  CellState state;
  state.robot.stamp = t;
  state.robot.q = scene_.motion ? scene_.motion->q_at(t) : scene_.sweep.stops.front();
  state.obstacles = scene_.obstacles;
  for (const Carry& carry : carries_) {
    if (t < carry.pick_time) continue;
    const int index = [&] {
      for (std::size_t i = 0; i < state.obstacles.size(); ++i) {
        if (state.obstacles[i].name == carry.name) return static_cast<int>(i);
      }
      return -1;
    }();
    if (index >= 0) state.obstacles.erase(state.obstacles.begin() + index);
    if (t < carry.place_time) {
      state.robot.payload = carry.payload;
    } else {
      state.obstacles.push_back(carry.placed);
    }
  }
  for (const Walker& walker : scene_.walkers) {
    for (Obstacle& part : walker.at(t)) state.obstacles.push_back(std::move(part));
  }
  return state;
}

SimWindow Simulator::window(double t0, double t1, const std::vector<int>& sensors) const {
  if (!(t0 >= 0) || !(t1 >= t0)) throw Error("simulator: window needs 0 <= t0 <= t1");
  std::vector<int> rendered = sensors;
  if (sensors.empty()) {
    for (int sensor = 0; sensor < static_cast<int>(scene_.sensors.size()); ++sensor)
      rendered.push_back(sensor);
  }
  SimWindow out;
  for (const int sensor : rendered) {
    if (sensor < 0 || sensor >= static_cast<int>(scene_.sensors.size()))
      throw Error("simulator: no sensor with index " + std::to_string(sensor));
    const SensorSpec& spec = scene_.sensors[static_cast<std::size_t>(sensor)];
    const double period = scene_.plan_for(spec).period;
    for (long k = first_tick(t0, period); static_cast<double>(k) * period < t1; ++k) {
      const double t = static_cast<double>(k) * period;
      const CellState state = state_at(t);
      out.frames.push_back(render_in(sensor, state.robot, state.obstacles,
                                     NoiseKey{spec.seed, 0, static_cast<std::uint64_t>(k)}));
    }
  }
  std::stable_sort(out.frames.begin(), out.frames.end(),
                   [](const SimFrame& a, const SimFrame& b) { return a.frame.stamp < b.frame.stamp; });
  const double rate = scene_.motion ? scene_.motion->controller_rate : 250.0;
  const double delay = scene_.motion ? scene_.motion->joint_stamp_delay : 0.0;
  for (long k = first_tick(t0, 1.0 / rate); static_cast<double>(k) / rate < t1; ++k) {
    JointState sample = state_at(static_cast<double>(k) / rate).robot;
    sample.stamp += delay;
    out.joints.push_back(std::move(sample));
  }
  return out;
}

std::string Simulator::apply(const transport::SceneEdit& edit) {
  std::string name = sim::apply(scene_, edit);
  caster_ = SceneCaster(scene_.obstacles);
  return name;
}

SimFrame Simulator::render(int sensor, const Eigen::VectorXd& q, double stamp, std::uint64_t sweep_index,
                           std::uint64_t frame_index) const {
  return render(sensor, JointState{stamp, q, std::nullopt}, sweep_index, frame_index);
}

SimFrame Simulator::render(int sensor, const JointState& state, std::uint64_t sweep_index,
                           std::uint64_t frame_index) const {
  if (sensor < 0 || sensor >= static_cast<int>(scene_.sensors.size())) {
    throw Error("simulator: no sensor with index " + std::to_string(sensor));
  }
  const SensorSpec& spec = scene_.sensors[static_cast<std::size_t>(sensor)];
  return render_in(sensor, state, scene_.obstacles, NoiseKey{spec.seed, sweep_index, frame_index});
}

SimFrame Simulator::render_in(int sensor, const JointState& state, const std::vector<Obstacle>& obstacles,
                              const NoiseKey& key) const {
  const SensorSpec& spec = scene_.sensors[static_cast<std::size_t>(sensor)];
  const Eigen::Isometry3d X_CS = scene_.sensor_pose(sensor, state.q);
  const bool with_robot = options_.render_robot && (!scene_.robot.shapes().empty() || state.payload);
  const bool same_obstacles = &obstacles == &scene_.obstacles;
  const SceneCaster caster = with_robot       ? SceneCaster(obstacles, robot_solids_, state)
                             : same_obstacles ? caster_
                                              : SceneCaster(obstacles);
  SimFrame out =
      spec.is_camera() ? render_camera(spec, X_CS, key, caster) : render_scanner(spec, X_CS, key, caster);
  out.q = state.q;
  out.frame.sensor = spec.name;
  out.frame.stamp = state.stamp;
  out.frame.X_CS = X_CS;
  if (!spec.is_camera()) out.frame.field_of_view = spec.scanner.field_of_view();
  return out;
}

std::vector<SimFrame> Simulator::sweep(int sensor, std::uint64_t sweep_index, double start_stamp) const {
  if (sensor < 0 || sensor >= static_cast<int>(scene_.sensors.size())) {
    throw Error("simulator: no sensor with index " + std::to_string(sensor));
  }
  const SweepPlan& plan = scene_.plan_for(scene_.sensors[static_cast<std::size_t>(sensor)]);
  std::vector<SimFrame> frames;
  frames.reserve(plan.stops.size());
  for (std::size_t k = 0; k < plan.stops.size(); ++k) {
    frames.push_back(
        render(sensor, plan.stops[k], start_stamp + static_cast<double>(k) * plan.period, sweep_index, k));
  }
  return frames;
}

SimFrame Simulator::render_camera(const SensorSpec& spec, const Eigen::Isometry3d& X_CS, const NoiseKey& key,
                                  const SceneCaster& caster) const {
  SimFrame out = cast_pixels(spec.intrinsics, X_CS, scene_.cell, caster, options_.threads);
  const NoiseModel model = options_.noise ? noise_model(spec.model, spec.intrinsics) : zero_noise();
  const std::vector<double> noisy = apply_camera_noise(model, out.exact, spec.intrinsics.width,
                                                       spec.intrinsics.height, key, options_.threads);
  DepthImage image = quantized(noisy, spec.intrinsics, X_CS, scene_.cell);
  out.frame.points_S = depth_to_points(image);
  out.frame.depth = std::move(image);
  return out;
}

SimFrame Simulator::render_scanner(const SensorSpec& spec, const Eigen::Isometry3d& X_CS, const NoiseKey& key,
                                   const SceneCaster& caster) const {
  const LineScanner& s = spec.scanner;
  const std::size_t beams = static_cast<std::size_t>(s.beams);
  const Eigen::Vector3d p_CS = X_CS.translation();
  auto beam_S = [&](std::size_t i) {
    const double angle = -s.fov / 2 + s.fov * static_cast<double>(i) / static_cast<double>(beams - 1);
    return Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
  };

  SimFrame out;
  out.exact.assign(beams, 0.0);
  out.hit.assign(beams, RayHit::kNothing);
  for (std::size_t i = 0; i < beams; ++i) {
    const Eigen::Vector3d d_C = X_CS.linear() * beam_S(i);
    const double t_max = std::min(exit_distance(scene_.cell, p_CS, d_C), s.max_range);
    const RayHit hit = caster.cast(p_CS, d_C, t_max);
    if (hit.obstacle == RayHit::kNothing || hit.t < s.min_range) continue;
    out.exact[i] = hit.t;
    out.hit[i] = hit.obstacle;
  }

  const NoiseModel model = options_.noise ? noise_model(spec.model) : zero_noise();
  const std::vector<double> noisy = apply_range_noise(model, out.exact, key);
  Cloud& points = out.frame.points_S;
  for (std::size_t i = 0; i < beams; ++i) {
    if (noisy[i] <= 0) continue;
    const double r = std::round(noisy[i] / s.range_resolution) * s.range_resolution;
    if (r < s.min_range || r > s.max_range) continue;
    const Eigen::Vector3d p_S = beam_S(i) * r;
    if (!scene_.cell.contains(X_CS * p_S)) continue;
    points.push_back(
        pcl::PointXYZ(static_cast<float>(p_S.x()), static_cast<float>(p_S.y()), static_cast<float>(p_S.z())));
  }
  set_unorganized(points);
  return out;
}

}  // namespace cellmap::sim
