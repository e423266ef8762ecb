// SPDX-License-Identifier: Apache-2.0
#pragma once
// The sensor noise models of the paper's three sensors, applied to exact (ray-cast) depths and ranges.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.
//
// Deterministic by construction: every random number is a hash of (seed, sweep, frame, pixel, purpose), so a
// pixel's noise does not depend on the order of evaluation, the thread count or the rest of the scene — two
// renders of the same stop with the same seed differ only where the geometry differs.

#include <cstdint>
#include <vector>

#include "cellmap/frame/frame.hpp"
#include "cellmap/sim/scene.hpp"

namespace cellmap::sim {

/// Which frame of which sweep the noise is for.
struct NoiseKey final {
  std::uint64_t seed = 1;
  std::uint64_t sweep = 0;
  std::uint64_t frame = 0;
};

/// Parameters of one sensor's noise. Axial noise σ(z) = sigma_0 + sigma_z2·z² (metres) is drawn from a normal
/// distribution truncated at ±truncation·σ, so the bound below is a hard bound, not a probability.
struct NoiseModel final {
  double sigma_0 = 0.0;
  double sigma_z2 = 0.0;  ///< 1/m
  double truncation = 3.0;
  /// Surface waviness (stereo): a smooth image-space field in [-1, 1] times wave_amplitude·σ(z).
  double wave_amplitude = 0.0;
  double wave_length_px = 0.0;  ///< typical wavelength of the waviness at 640 px image width
  /// Neighbouring exact depths that differ by more than edge_threshold_0 + edge_threshold_z·z form a depth
  /// edge.
  double edge_threshold_0 = 0.03;
  double edge_threshold_z = 0.02;
  /// Time of flight: probability that a pixel on a depth edge returns a mix of the near and far depth.
  double flying_probability = 0.0;
  /// Stereo: pixels up to this many pixels behind a depth edge are pulled towards the near side (0 = off).
  int smear_radius = 0;

  [[nodiscard]] double sigma(double z) const { return sigma_0 + sigma_z2 * z * z; }
  [[nodiscard]] double edge_threshold(double z) const { return edge_threshold_0 + edge_threshold_z * z; }
  /// Largest |noisy − exact| depth (or range), metres, on a pixel farther than edge_radius() from any depth
  /// edge; quantization comes on top (half a depth unit).
  [[nodiscard]] double bound(double z) const { return (truncation + wave_amplitude) * sigma(z); }
  /// How far (pixels, Chebyshev) from a depth edge the edge effects reach.
  [[nodiscard]] int edge_radius() const;
  [[nodiscard]] bool is_zero() const;
};

/// No noise at all: the exact depth, quantized to the depth unit.
[[nodiscard]] NoiseModel zero_noise();
/// The model of `model`. The RealSense's stereo noise grows as z²·subpixel/(fx·baseline), so it depends on
/// the focal length of the chosen depth mode (`intrinsics.fx`; ignored for the other models).
[[nodiscard]] NoiseModel noise_model(SensorModel model, const PinholeIntrinsics& intrinsics = {});

/// Pixels within `radius` (Chebyshev) of a depth edge of the exact depth image (width × height, row-major,
/// metres, 0 = no return). An edge pixel is a valid pixel with a valid 8-neighbour nearer by more than the
/// model's edge threshold, or farther by more than it.
[[nodiscard]] std::vector<bool> near_depth_edge(const NoiseModel& model, const std::vector<double>& exact_z,
                                                int width, int height, int radius);

/// The noisy depth image (metres, 0 = no return) for exact depths `exact_z` (width × height, row-major).
/// `threads` share the per-pixel work; the result does not depend on it.
[[nodiscard]] std::vector<double> apply_camera_noise(const NoiseModel& model,
                                                     const std::vector<double>& exact_z, int width,
                                                     int height, const NoiseKey& key, int threads = 1);
/// The noisy ranges of a line scan (one per beam, metres, 0 = no return).
[[nodiscard]] std::vector<double> apply_range_noise(const NoiseModel& model,
                                                    const std::vector<double>& exact_r, const NoiseKey& key);

}  // namespace cellmap::sim
