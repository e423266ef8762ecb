#include "cellmap/frame/frame.hpp"

#include <algorithm>
#include <limits>
#include <vector>

#include "cellmap/common/error.hpp"

namespace cellmap {

void PinholeIntrinsics::validate() const {
  if (width <= 0 || height <= 0) throw Error("intrinsics: width and height must be positive");
  if (!(fx > 0) || !(fy > 0)) throw Error("intrinsics: fx and fy must be positive");
  if (!(depth_scale > 0)) throw Error("intrinsics: depth_scale must be positive");
  if (!(min_range >= 0) || !(max_range > min_range))
    throw Error("intrinsics: need 0 <= min_range < max_range");
  if (!(max_depth_jump >= 0)) throw Error("intrinsics: max_depth_jump must be >= 0");
}

namespace {

// Depth in metres of each pixel with a return in [min_range, max_range], else 0, written to `z`.
void valid_depths(const DepthImage& image, std::vector<double>& z) {
  const PinholeIntrinsics& k = image.intrinsics;
  z.resize(image.depth.size());
  for (std::size_t p = 0; p < z.size(); ++p) {
    const double d = image.depth[p] * k.depth_scale;
    z[p] = image.depth[p] != 0 && d >= k.min_range && d <= k.max_range ? d : 0.0;
  }
}

// Per pixel, the nearest valid depth (> 0) of `z` among the pixel and its 8 neighbours inside the image,
// +infinity where there is none, written to `nearest`: two passes of a 3-wide minimum (rows, then columns)
// that the compiler vectorizes. A pixel lies behind a depth edge exactly when its depth minus this minimum
// exceeds the limit: the difference is largest for the nearest neighbour (subtraction rounds monotonically),
// and the pixel itself (difference 0) never exceeds a limit ≥ 0.
// Written here rather than taken from PCL: its ShadowPoints filter needs normals of an organized cloud
// first, and the test on raw neighbours is a few comparisons per pixel.
void nearest_around(const std::vector<double>& z, int width, int height, std::vector<double>& rows,
                    std::vector<double>& nearest) {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  const std::size_t w = static_cast<std::size_t>(width);
  rows.resize(z.size());
  nearest.resize(z.size());
  for (int v = 0; v < height; ++v) {
    const double* in = &z[static_cast<std::size_t>(v) * w];
    double* out = &rows[static_cast<std::size_t>(v) * w];
    const auto valid = [](double d) { return d > 0 ? d : kNone; };
    for (std::size_t u = 0; u < w; ++u) {
      const double left = u > 0 ? valid(in[u - 1]) : kNone;
      const double right = u + 1 < w ? valid(in[u + 1]) : kNone;
      out[u] = std::min(std::min(left, valid(in[u])), right);
    }
  }
  for (int v = 0; v < height; ++v) {
    const double* row = &rows[static_cast<std::size_t>(v) * w];
    const double* above = v > 0 ? row - w : row;
    const double* below = v + 1 < height ? row + w : row;
    double* out = &nearest[static_cast<std::size_t>(v) * w];
    for (std::size_t u = 0; u < w; ++u) out[u] = std::min(std::min(above[u], row[u]), below[u]);
  }
}

}  // namespace

Cloud depth_to_points(const DepthImage& image, bool organized) {
  const PinholeIntrinsics& k = image.intrinsics;
  k.validate();
  const std::size_t pixels = static_cast<std::size_t>(k.width) * static_cast<std::size_t>(k.height);
  if (image.depth.size() != pixels) {
    throw Error("depth image: " + std::to_string(image.depth.size()) + " pixels, intrinsics say " +
                std::to_string(k.width) + "x" + std::to_string(k.height));
  }
  Cloud cloud;
  auto& points = cloud.points;  // filled directly: the cloud's push_back also rewrites width and height
  points.reserve(pixels);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const double inv_fx = 1.0 / k.fx;
  const double inv_fy = 1.0 / k.fy;
  // Kept per thread: frames' worth of doubles, fresh memory (zeroed and page-faulted) on every frame else.
  thread_local std::vector<double> depths, rows, nearest;
  valid_depths(image, depths);
  if (k.max_depth_jump > 0) nearest_around(depths, k.width, k.height, rows, nearest);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * k.width + u;
      const double z = depths[p];
      if (z == 0 || (k.max_depth_jump > 0 && z - nearest[p] > k.max_depth_jump * z)) {
        if (organized) points.emplace_back(nan, nan, nan);
        continue;
      }
      points.emplace_back(static_cast<float>((u - k.cx) * z * inv_fx),
                          static_cast<float>((v - k.cy) * z * inv_fy), static_cast<float>(z));
    }
  }
  if (organized) {
    cloud.width = static_cast<std::uint32_t>(k.width);
    cloud.height = static_cast<std::uint32_t>(k.height);
    cloud.is_dense = false;
  } else {
    cloud.width = static_cast<std::uint32_t>(cloud.size());
    cloud.height = 1;
    cloud.is_dense = true;
  }
  return cloud;
}

FieldOfView frustum(const PinholeIntrinsics& k) {
  k.validate();
  const auto ray = [&](double u, double v) {
    return Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0).normalized();
  };
  // Pixel (u, v) covers [u - 0.5, u + 0.5]: the image's outer edges lie half a pixel beyond the corner
  // pixels.
  const double left = -0.5, right = k.width - 0.5, top = -0.5, bottom = k.height - 0.5;
  return {{ray(left, top), ray(right, top), ray(right, bottom), ray(left, bottom)}, true, k.max_range};
}

std::optional<FieldOfView> field_of_view(const Frame& frame) {
  if (frame.field_of_view) return frame.field_of_view;
  if (frame.depth) return frustum(frame.depth->intrinsics);
  return std::nullopt;
}

}  // namespace cellmap
