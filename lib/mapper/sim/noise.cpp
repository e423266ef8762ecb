// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/noise.hpp"

#include "cellmap/common/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace cellmap::sim {
namespace {

// SplitMix64's finalizer: a fast bijective hash with good avalanche, so hash(key, pixel) acts as a random
// number generator that can be evaluated for any pixel in any order (what makes the noise order-free).
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// What a random number is used for, so that draws for the same pixel are independent.
enum Purpose : std::uint64_t { kGauss = 0, kFlying = 8, kMix = 9, kSmear = 10, kWave = 11 };

class Random {
 public:
  explicit Random(const NoiseKey& key) : base_(mix(mix(mix(key.seed) ^ key.sweep) ^ key.frame)) {}

  /// Uniform in [0, 1).
  [[nodiscard]] double uniform(std::uint64_t index, std::uint64_t purpose) const {
    return static_cast<double>(mix(base_ ^ mix(index * 16 + purpose)) >> 11) * 0x1p-53;
  }

  /// Standard normal truncated to [-limit, limit] by rejection (Box–Muller pairs, at most 4 tries; the
  /// chance of needing more is below 1e-9 for limit 3, and the last try is clamped).
  [[nodiscard]] double truncated_normal(std::uint64_t index, double limit) const {
    double z = 0;
    for (std::uint64_t attempt = 0; attempt < 4; ++attempt) {
      const double u1 = 1.0 - uniform(index, kGauss + 2 * attempt);  // (0, 1]
      const double u2 = uniform(index, kGauss + 2 * attempt + 1);
      z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2 * M_PI * u2);
      if (std::abs(z) <= limit) return z;
    }
    return std::clamp(z, -limit, limit);
  }

 private:
  std::uint64_t base_;
};

std::size_t at(int u, int v, int width) {
  return static_cast<std::size_t>(v) * width + u;
}

// Valid pixels next to (8-neighbourhood) a valid pixel whose depth differs by more than the edge threshold.
// `near_side` keeps only the nearer pixel of each such pair.
std::vector<bool> edge_pixels(const NoiseModel& model, const std::vector<double>& z, int width, int height,
                              bool near_side) {
  std::vector<bool> edge(z.size(), false);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double zp = z[at(u, v, width)];
      if (zp <= 0) continue;
      bool found = false;
      for (int dv = -1; dv <= 1 && !found; ++dv) {
        for (int du = -1; du <= 1 && !found; ++du) {
          const int nu = u + du, nv = v + dv;
          if ((du == 0 && dv == 0) || nu < 0 || nv < 0 || nu >= width || nv >= height) continue;
          const double zq = z[at(nu, nv, width)];
          if (zq <= 0) continue;
          const double jump = zq - zp;
          const double threshold = model.edge_threshold(std::min(zp, zq));
          found = near_side ? jump > threshold : std::abs(jump) > threshold;
        }
      }
      edge[at(u, v, width)] = found;
    }
  }
  return edge;
}

// Chebyshev dilation by `radius`, separably: along rows, then along columns.
std::vector<bool> dilate(const std::vector<bool>& mask, int width, int height, int radius) {
  if (radius <= 0) return mask;
  std::vector<bool> rows(mask.size(), false);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (!mask[at(u, v, width)]) continue;
      for (int k = std::max(0, u - radius); k <= std::min(width - 1, u + radius); ++k)
        rows[at(k, v, width)] = true;
    }
  }
  std::vector<bool> out(mask.size(), false);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (!rows[at(u, v, width)]) continue;
      for (int k = std::max(0, v - radius); k <= std::min(height - 1, v + radius); ++k)
        out[at(u, k, width)] = true;
    }
  }
  return out;
}

// Smooth field in [-1, 1]: the mean of three plane waves with random direction, wavelength and phase.
// sin(ku·u + kv·v + φ) = sin(ku·u)·cos(kv·v + φ) + cos(ku·u)·sin(kv·v + φ): per-column and per-row tables
// make a pixel cost six multiply-adds instead of three sines.
class Waviness {
 public:
  Waviness(const Random& random, double wave_length_px, int width, int height) {
    const double scale = width / 640.0;
    for (int k = 0; k < 3; ++k) {
      const auto index = static_cast<std::uint64_t>(k);
      const double theta = 2 * M_PI * random.uniform(index, kWave);
      const double length = wave_length_px * scale * (0.6 + 0.8 * random.uniform(index, kWave + 1));
      const double ku = 2 * M_PI * std::cos(theta) / length, kv = 2 * M_PI * std::sin(theta) / length;
      const double phase = 2 * M_PI * random.uniform(index, kWave + 2);
      for (int u = 0; u < width; ++u) {
        column_sin_[k].push_back(std::sin(ku * u));
        column_cos_[k].push_back(std::cos(ku * u));
      }
      for (int v = 0; v < height; ++v) {
        row_sin_[k].push_back(std::sin(kv * v + phase));
        row_cos_[k].push_back(std::cos(kv * v + phase));
      }
    }
  }
  [[nodiscard]] double at(int u, int v) const {
    double sum = 0;
    for (int k = 0; k < 3; ++k) {
      sum += column_sin_[k][static_cast<std::size_t>(u)] * row_cos_[k][static_cast<std::size_t>(v)] +
             column_cos_[k][static_cast<std::size_t>(u)] * row_sin_[k][static_cast<std::size_t>(v)];
    }
    return sum / 3.0;
  }

 private:
  std::vector<double> column_sin_[3], column_cos_[3], row_sin_[3], row_cos_[3];
};

}  // namespace

int NoiseModel::edge_radius() const {
  int radius = 0;
  if (flying_probability > 0) radius = std::max(radius, 1);
  return std::max(radius, smear_radius);
}

bool NoiseModel::is_zero() const {
  return sigma_0 == 0 && sigma_z2 == 0 && wave_amplitude == 0 && flying_probability == 0 && smear_radius == 0;
}

NoiseModel zero_noise() {
  return NoiseModel{};
}

NoiseModel noise_model(SensorModel model, const PinholeIntrinsics& intrinsics) {
  NoiseModel m;
  switch (model) {
    case SensorModel::kKinectV2:
      // Time of flight: ~1.5 mm axial noise at 1 m growing slowly with range (Fankhauser et al. 2015 measured
      // 1.5–4 mm up to 3 m), and flying pixels where a pixel's footprint straddles a depth edge.
      m.sigma_0 = 0.001;
      m.sigma_z2 = 0.0005;
      m.flying_probability = 0.5;
      return m;
    case SensorModel::kRealsenseD435:
      // Active stereo: depth error = z² · subpixel disparity error / (focal length · baseline); D435 baseline
      // 50 mm, subpixel error ~0.08 px (Intel's tuning white paper). Correlated matching error shows as
      // surface waviness; edge fattening of the block matcher smears depth edges over a few pixels.
      m.sigma_0 = 0.0;
      m.sigma_z2 = 0.08 / ((intrinsics.fx > 0 ? intrinsics.fx : 383.0) * 0.050);
      m.wave_amplitude = 1.5;
      m.wave_length_px = 80.0;
      m.smear_radius = 3;
      return m;
    case SensorModel::kOs32c:
      // Safety laser scanner: millimetre-level range noise, one return per beam, sharp edges.
      m.sigma_0 = 0.002;
      return m;
  }
  return m;
}

std::vector<bool> near_depth_edge(const NoiseModel& model, const std::vector<double>& exact_z, int width,
                                  int height, int radius) {
  return dilate(edge_pixels(model, exact_z, width, height, false), width, height, radius);
}

namespace {

// Flying pixels: an edge pixel integrates light from both surfaces, so its phase, and so its depth, lands in
// between (with model.flying_probability).
void add_flying_pixels(const NoiseModel& model, const Random& random, const std::vector<double>& exact_z,
                       int width, int height, int threads, std::vector<double>& z) {
  const std::vector<bool> edge = edge_pixels(model, exact_z, width, height, false);
  parallel_for(height, threads, [&](int v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t p = at(u, v, width);
      if (!edge[p] || random.uniform(p, kFlying) >= model.flying_probability) continue;
      double lo = exact_z[p], hi = exact_z[p];
      for (int nv = std::max(0, v - 1); nv <= std::min(height - 1, v + 1); ++nv) {
        for (int nu = std::max(0, u - 1); nu <= std::min(width - 1, u + 1); ++nu) {
          const double zq = exact_z[at(nu, nv, width)];
          if (zq > 0) lo = std::min(lo, zq), hi = std::max(hi, zq);
        }
      }
      z[p] = lo + random.uniform(p, kMix) * (hi - lo);
    }
  });
}

// Stereo smear: the nearest near-side edge pixel in front of a background pixel within model.smear_radius
// overlaps the block matcher's window and the foreground's texture wins, so the background is pulled towards
// the foreground depth.
void smear_edges(const NoiseModel& model, const Random& random, const std::vector<double>& exact_z, int width,
                 int height, int threads, std::vector<double>& z) {
  const int r = model.smear_radius;
  const std::vector<bool> near_edge = edge_pixels(model, exact_z, width, height, true);
  const std::vector<bool> reach = dilate(near_edge, width, height, r);  // only these can be smeared
  parallel_for(height, threads, [&](int v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t p = at(u, v, width);
      const double zp = exact_z[p];
      if (zp <= 0 || !reach[p]) continue;
      double best_d2 = (r + 0.5) * (r + 0.5);
      double z_front = 0;
      for (int nv = std::max(0, v - r); nv <= std::min(height - 1, v + r); ++nv) {
        for (int nu = std::max(0, u - r); nu <= std::min(width - 1, u + r); ++nu) {
          const std::size_t q = at(nu, nv, width);
          if (!near_edge[q] || !(exact_z[q] < zp - model.edge_threshold(exact_z[q]))) continue;
          const double d2 = static_cast<double>((nu - u) * (nu - u) + (nv - v) * (nv - v));
          if (d2 < best_d2) best_d2 = d2, z_front = exact_z[q];
        }
      }
      if (z_front <= 0) continue;
      const double s = (std::sqrt(best_d2) + 0.5 * random.uniform(p, kSmear)) / (r + 1.0);
      z[p] = z_front + std::min(s, 1.0) * (zp - z_front);
    }
  });
}

// Depth noise of every returning pixel: white (truncated normal) plus, where the model has it, a smooth
// waviness field; negative depths clamp to 0.
void add_depth_noise(const NoiseModel& model, const Random& random, int width, int height, int threads,
                     std::vector<double>& z) {
  const bool wavy = model.wave_amplitude > 0;
  const Waviness wave(random, wavy ? model.wave_length_px : 1.0, wavy ? width : 0, wavy ? height : 0);
  parallel_for(height, threads, [&](int v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t p = at(u, v, width);
      if (z[p] <= 0) continue;
      const double sigma = model.sigma(z[p]);
      double noisy = z[p] + sigma * random.truncated_normal(p, model.truncation);
      if (wavy) noisy += model.wave_amplitude * sigma * wave.at(u, v);
      z[p] = std::max(noisy, 0.0);
    }
  });
}

}  // namespace

std::vector<double> apply_camera_noise(const NoiseModel& model, const std::vector<double>& exact_z, int width,
                                       int height, const NoiseKey& key, int threads) {
  if (model.is_zero()) return exact_z;
  const Random random(key);
  std::vector<double> z = exact_z;
  if (model.flying_probability > 0) add_flying_pixels(model, random, exact_z, width, height, threads, z);
  if (model.smear_radius > 0) smear_edges(model, random, exact_z, width, height, threads, z);
  add_depth_noise(model, random, width, height, threads, z);
  return z;
}

std::vector<double> apply_range_noise(const NoiseModel& model, const std::vector<double>& exact_r,
                                      const NoiseKey& key) {
  if (model.is_zero()) return exact_r;
  const Random random(key);
  std::vector<double> r = exact_r;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (r[i] <= 0) continue;
    r[i] = std::max(r[i] + model.sigma(r[i]) * random.truncated_normal(i, model.truncation), 0.0);
  }
  return r;
}

}  // namespace cellmap::sim
