#include "cellmap/sim/simulator.hpp"

#include <algorithm>
#include <cmath>

#include "cellmap/common/error.hpp"
#include "cellmap/common/parallel.hpp"

namespace cellmap::sim {
namespace {

constexpr int kTile = 16;  // pixels per side of the tiles that share one candidate list

Scene validated(Scene scene) {
  scene.validate();
  return scene;
}

}  // namespace

Simulator::Simulator(Scene scene, SimOptions options)
    : scene_(validated(std::move(scene))), options_(options), caster_(scene_.obstacles) {}

std::string Simulator::apply(const transport::SceneEdit& edit) {
  std::string name = sim::apply(scene_, edit);
  caster_ = SceneCaster(scene_.obstacles);
  return name;
}

SimFrame Simulator::render(int sensor, const Eigen::VectorXd& q, double stamp, std::uint64_t sweep_index,
                           std::uint64_t frame_index) const {
  if (sensor < 0 || sensor >= static_cast<int>(scene_.sensors.size())) {
    throw Error("simulator: no sensor with index " + std::to_string(sensor));
  }
  const SensorSpec& spec = scene_.sensors[static_cast<std::size_t>(sensor)];
  const Eigen::Isometry3d X_CS = scene_.sensor_pose(sensor, q);
  const NoiseKey key{spec.seed, sweep_index, frame_index};
  SimFrame out = spec.is_camera() ? render_camera(spec, X_CS, key) : render_scanner(spec, X_CS, key);
  out.q = q;
  out.frame.sensor = spec.name;
  out.frame.stamp = stamp;
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

SimFrame Simulator::render_camera(const SensorSpec& spec, const Eigen::Isometry3d& X_CS,
                                  const NoiseKey& key) const {
  const PinholeIntrinsics& k = spec.intrinsics;
  const int width = k.width, height = k.height;
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const Eigen::Matrix3d R_CS = X_CS.linear();
  const Eigen::Vector3d p_CS = X_CS.translation();
  // Unnormalised ray of pixel (u, v) in S; its z component is 1, so depth z = t / |ray|.
  auto ray_S = [&](double u, double v) { return Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0); };

  SimFrame out;
  out.exact.assign(pixels, 0.0);
  out.hit.assign(pixels, -1);
  const int tiles_u = (width + kTile - 1) / kTile, tiles_v = (height + kTile - 1) / kTile;
  parallel_for(tiles_u * tiles_v, options_.threads, [&](int tile) {
    const int u0 = (tile % tiles_u) * kTile, v0 = (tile / tiles_u) * kTile;
    const int u1 = std::min(width, u0 + kTile) - 1, v1 = std::min(height, v0 + kTile) - 1;
    // The cone around the tile's four corner rays holds every ray of the tile (the tile is convex on the
    // image plane); obstacles outside it cannot be hit from this tile.
    const Eigen::Vector3d corners[4] = {ray_S(u0, v0).normalized(), ray_S(u1, v0).normalized(),
                                        ray_S(u0, v1).normalized(), ray_S(u1, v1).normalized()};
    const Eigen::Vector3d axis_S = (corners[0] + corners[1] + corners[2] + corners[3]).normalized();
    double half_angle = 0;
    for (const Eigen::Vector3d& c : corners) {
      half_angle = std::max(half_angle, std::acos(std::clamp(axis_S.dot(c), -1.0, 1.0)));
    }
    const std::vector<SceneCaster::Candidate> candidates =
        caster_.candidates(p_CS, R_CS * axis_S, half_angle + 1e-9);
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        const Eigen::Vector3d r_S = ray_S(u, v);
        const double length = r_S.norm();
        const Eigen::Vector3d d_C = R_CS * (r_S / length);
        const double t_max = std::min(exit_distance(scene_.cell, p_CS, d_C), k.max_range * length);
        const RayHit hit = caster_.cast(p_CS, d_C, t_max, &candidates);
        if (hit.obstacle < 0) continue;
        const double z = hit.t / length;
        if (z < k.min_range || z > k.max_range) continue;
        const std::size_t p = static_cast<std::size_t>(v) * width + u;
        out.exact[p] = z;
        out.hit[p] = hit.obstacle;
      }
    }
  });

  const NoiseModel model = options_.noise ? noise_model(spec.model, k) : zero_noise();
  const std::vector<double> noisy =
      apply_camera_noise(model, out.exact, width, height, key, options_.threads);

  // Quantize like the camera does (raw units of depth_scale, 0 = no return) and drop what lies outside the
  // cell.
  DepthImage image;
  image.intrinsics = k;
  image.depth.assign(pixels, 0);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * width + u;
      if (noisy[p] <= 0) continue;
      const double raw = std::round(noisy[p] / k.depth_scale);
      const double z = raw * k.depth_scale;
      if (raw < 1 || raw > 65535 || z < k.min_range || z > k.max_range) continue;
      if (!scene_.cell.contains(X_CS * (ray_S(u, v) * z))) continue;
      image.depth[p] = static_cast<std::uint16_t>(raw);
    }
  }
  out.frame.points_S = depth_to_points(image);
  out.frame.depth = std::move(image);
  return out;
}

SimFrame Simulator::render_scanner(const SensorSpec& spec, const Eigen::Isometry3d& X_CS,
                                   const NoiseKey& key) const {
  const LineScanner& s = spec.scanner;
  const std::size_t beams = static_cast<std::size_t>(s.beams);
  const Eigen::Vector3d p_CS = X_CS.translation();
  auto beam_S = [&](std::size_t i) {
    const double angle = -s.fov / 2 + s.fov * static_cast<double>(i) / static_cast<double>(beams - 1);
    return Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
  };

  SimFrame out;
  out.exact.assign(beams, 0.0);
  out.hit.assign(beams, -1);
  for (std::size_t i = 0; i < beams; ++i) {
    const Eigen::Vector3d d_C = X_CS.linear() * beam_S(i);
    const double t_max = std::min(exit_distance(scene_.cell, p_CS, d_C), s.max_range);
    const RayHit hit = caster_.cast(p_CS, d_C, t_max);
    if (hit.obstacle < 0 || hit.t < s.min_range) continue;
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
  points.width = static_cast<std::uint32_t>(points.size());
  points.height = 1;
  points.is_dense = true;
  return out;
}

}  // namespace cellmap::sim
