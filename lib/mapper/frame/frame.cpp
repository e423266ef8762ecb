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

// Depth in metres of each pixel with a return in [min_range, max_range], else 0.
std::vector<double> valid_depths(const DepthImage& image) {
  const PinholeIntrinsics& k = image.intrinsics;
  std::vector<double> z(image.depth.size(), 0.0);
  for (std::size_t p = 0; p < z.size(); ++p) {
    const double d = image.depth[p] * k.depth_scale;
    if (image.depth[p] != 0 && d >= k.min_range && d <= k.max_range) z[p] = d;
  }
  return z;
}

// Whether a valid 8-neighbour of pixel (u, v) is nearer by more than max_jump of the pixel's depth.
// Written here rather than taken from PCL: its ShadowPoints filter needs normals of an organized cloud
// first, and the test on raw neighbours is a few comparisons per pixel.
bool behind_depth_edge(const std::vector<double>& z, int width, int height, int u, int v, double max_jump) {
  const double zp = z[static_cast<std::size_t>(v) * width + u];
  const double limit = max_jump * zp;
  for (int nv = std::max(0, v - 1); nv <= std::min(height - 1, v + 1); ++nv) {
    for (int nu = std::max(0, u - 1); nu <= std::min(width - 1, u + 1); ++nu) {
      const double zq = z[static_cast<std::size_t>(nv) * width + nu];
      if (zq > 0 && zp - zq > limit) return true;
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
  cloud.reserve(pixels);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const double inv_fx = 1.0 / k.fx;
  const double inv_fy = 1.0 / k.fy;
  const std::vector<double> depths = valid_depths(image);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const double z = depths[static_cast<std::size_t>(v) * k.width + u];
      if (z == 0 ||
          (k.max_depth_jump > 0 && behind_depth_edge(depths, k.width, k.height, u, v, k.max_depth_jump))) {
        if (organized) cloud.push_back(pcl::PointXYZ(nan, nan, nan));
        continue;
      }
      cloud.push_back(pcl::PointXYZ(static_cast<float>((u - k.cx) * z * inv_fx),
                                    static_cast<float>((v - k.cy) * z * inv_fy), static_cast<float>(z)));
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
