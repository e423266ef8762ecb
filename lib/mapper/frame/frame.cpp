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

// Whether valid depth `zq` of a neighbour is nearer than `zp` by more than `limit`.
inline bool nearer(double zp, double zq, double limit) {
  return zq > 0 && zp - zq > limit;
}

// Whether a valid 8-neighbour of pixel (u, v) is nearer by more than max_jump of the pixel's depth.
// Written here rather than taken from PCL: its ShadowPoints filter needs normals of an organized cloud
// first, and the test on raw neighbours is a few comparisons per pixel.
bool behind_depth_edge(const std::vector<double>& z, int width, int height, int u, int v, double max_jump) {
  const double zp = z[static_cast<std::size_t>(v) * width + u];
  const double limit = max_jump * zp;
  if (u > 0 && v > 0 && u + 1 < width && v + 1 < height) {  // inside: no bounds to check
    const double* above = &z[static_cast<std::size_t>(v - 1) * width + u];
    const double* row = above + width;
    const double* below = row + width;
    return nearer(zp, above[-1], limit) || nearer(zp, above[0], limit) || nearer(zp, above[1], limit) ||
           nearer(zp, row[-1], limit) || nearer(zp, row[1], limit) || nearer(zp, below[-1], limit) ||
           nearer(zp, below[0], limit) || nearer(zp, below[1], limit);
  }
  for (int nv = std::max(0, v - 1); nv <= std::min(height - 1, v + 1); ++nv) {
    for (int nu = std::max(0, u - 1); nu <= std::min(width - 1, u + 1); ++nu) {
      if (nearer(zp, z[static_cast<std::size_t>(nv) * width + nu], limit)) return true;
    }
  }
  return false;
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
  // Kept per thread: a frame's worth of doubles, fresh memory (zeroed and page-faulted) on every frame else.
  thread_local std::vector<double> depths;
  valid_depths(image, depths);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const double z = depths[static_cast<std::size_t>(v) * k.width + u];
      if (z == 0 ||
          (k.max_depth_jump > 0 && behind_depth_edge(depths, k.width, k.height, u, v, k.max_depth_jump))) {
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
