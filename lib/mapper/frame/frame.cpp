#include "cellmap/frame/frame.hpp"

#include <limits>

#include "cellmap/common/error.hpp"

namespace cellmap {

void PinholeIntrinsics::validate() const {
  if (width <= 0 || height <= 0) throw Error("intrinsics: width and height must be positive");
  if (!(fx > 0) || !(fy > 0)) throw Error("intrinsics: fx and fy must be positive");
  if (!(depth_scale > 0)) throw Error("intrinsics: depth_scale must be positive");
  if (!(min_range >= 0) || !(max_range > min_range))
    throw Error("intrinsics: need 0 <= min_range < max_range");
}

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
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::uint16_t raw = image.depth[static_cast<std::size_t>(v) * k.width + u];
      const double z = raw * k.depth_scale;
      if (raw == 0 || z < k.min_range || z > k.max_range) {
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
