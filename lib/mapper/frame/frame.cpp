// SPDX-License-Identifier: Apache-2.0
#include "cellmap/frame/frame.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
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
  if (smoothing_radius < 0 || smoothing_radius > kMaxSmoothingRadius)
    throw Error("intrinsics: smoothing_radius must be in [0, " + std::to_string(kMaxSmoothingRadius) + "]");
}

namespace {

// Raw depth of each pixel with a return in [min_range, max_range], else 0, written to `raw`.
void valid_depths(const DepthImage& image, std::vector<std::uint16_t>& raw) {
  const PinholeIntrinsics& k = image.intrinsics;
  raw.resize(image.depth.size());
  for (std::size_t p = 0; p < raw.size(); ++p) {
    const double d = image.depth[p] * k.depth_scale;
    raw[p] = d >= k.min_range && d <= k.max_range ? image.depth[p] : 0;
  }
}

// Depth smoothing's sums: for each of `count` pixels, `other`'s depth where it is valid and within `limit` of
// the pixel's own (`centre`), added to `sum` and counted in `n`. Branch-free, so that it vectorizes.
void add_neighbours(const std::uint16_t* centre, const std::uint16_t* other, const std::uint32_t* limit,
                    std::uint32_t* sum, std::uint32_t* n, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t d = centre[i], e = other[i];
    const std::uint32_t near = (e > d ? e - d : d - e) <= limit[i];
    const std::uint32_t take = near & (e != 0);
    sum[i] += take * e;
    n[i] += take;
  }
}

// The depth smoothing (PinholeIntrinsics::smoothing_radius): each valid depth becomes the mean of the valid
// depths within the radius along its row that lie within max_depth_jump of it, then the same along its
// column. Written here rather than taken from PCL: its bilateral filters work on an organized cloud with a
// range kernel fixed in metres, where stereo noise grows with z² and a frame must cost a few milliseconds.
void smooth_depths(std::vector<std::uint16_t>& raw, const PinholeIntrinsics& k,
                   std::vector<std::uint16_t>& scratch) {
  const std::size_t w = static_cast<std::size_t>(k.width);
  const int r = k.smoothing_radius;
  thread_local std::vector<std::uint32_t> limit, sum, n;
  limit.resize(w), sum.resize(w), n.resize(w);
  // 1 / n for the counts a window can have (a division per pixel would cost more than the sums); 0 for none,
  // which only a pixel without a return has (a valid pixel counts itself).
  std::array<float, 2 * kMaxSmoothingRadius + 2> inverse{};
  for (std::size_t c = 1; c < inverse.size(); ++c) inverse[c] = 1.0f / static_cast<float>(c);
  const auto mean_into = [&](std::uint16_t* out) {
    for (std::size_t u = 0; u < w; ++u)
      out[u] = static_cast<std::uint16_t>(static_cast<float>(sum[u]) * inverse[n[u]] + 0.5f);
  };
  const auto start = [&](const std::uint16_t* centre) {
    for (std::size_t u = 0; u < w; ++u) limit[u] = static_cast<std::uint32_t>(k.max_depth_jump * centre[u]);
    std::fill(sum.begin(), sum.end(), 0u);
    std::fill(n.begin(), n.end(), 0u);
  };
  scratch.resize(raw.size());
  for (int v = 0; v < k.height; ++v) {  // along the rows: raw → scratch
    const std::uint16_t* row = &raw[static_cast<std::size_t>(v) * w];
    start(row);
    for (int o = -r; o <= r; ++o) {
      const std::size_t from = static_cast<std::size_t>(std::max(0, -o));
      const std::size_t to = w - static_cast<std::size_t>(std::max(0, o));
      if (from < to)
        add_neighbours(row + from, row + from + o, &limit[from], &sum[from], &n[from], to - from);
    }
    mean_into(&scratch[static_cast<std::size_t>(v) * w]);
  }
  for (int v = 0; v < k.height; ++v) {  // along the columns: scratch → raw
    const std::uint16_t* row = &scratch[static_cast<std::size_t>(v) * w];
    start(row);
    for (int o = std::max(-r, -v); o <= std::min(r, k.height - 1 - v); ++o)
      add_neighbours(row, row + static_cast<std::ptrdiff_t>(o) * static_cast<std::ptrdiff_t>(w), limit.data(),
                     sum.data(), n.data(), w);
    mean_into(&raw[static_cast<std::size_t>(v) * w]);
  }
}

// Stands for "no valid depth" in a minimum: a valid pixel is never nearer, and a pixel's own depth is part
// of its minimum, so a neighbour without a return never lowers it.
constexpr std::uint16_t kNoReturn = std::numeric_limits<std::uint16_t>::max();

// Per pixel, the nearest valid raw depth of the pixel and its left and right neighbours inside the row
// (kNoReturn where there is none), written to `rows`: the first pass of a 3 × 3 minimum, whose second pass
// (above, this, below) runs as the points are made. Kept in raw units: metres are raw × depth_scale, which
// keeps the order, so the minimum in metres is the minimum in raw units times the scale, exactly.
// A pixel lies behind a depth edge exactly when its depth minus this minimum exceeds the limit: the
// difference is largest for the nearest neighbour (subtraction rounds monotonically), and the pixel itself
// (difference 0) never exceeds a limit ≥ 0. Written here rather than taken from PCL: its ShadowPoints
// filter needs normals of an organized cloud first, and the test on raw neighbours is a few comparisons
// per pixel.
void nearest_in_rows(const std::vector<std::uint16_t>& raw, int width, int height,
                     std::vector<std::uint16_t>& rows) {
  const std::size_t w = static_cast<std::size_t>(width);
  rows.resize(raw.size());
  const auto valid = [](std::uint16_t d) { return d != 0 ? d : kNoReturn; };
  for (int v = 0; v < height; ++v) {
    const std::uint16_t* in = &raw[static_cast<std::size_t>(v) * w];
    std::uint16_t* out = &rows[static_cast<std::size_t>(v) * w];
    if (w == 1) {
      out[0] = valid(in[0]);
      continue;
    }
    out[0] = std::min(valid(in[0]), valid(in[1]));
    for (std::size_t u = 1; u + 1 < w; ++u)  // vectorized: no border test inside
      out[u] = std::min(std::min(valid(in[u - 1]), valid(in[u])), valid(in[u + 1]));
    out[w - 1] = std::min(valid(in[w - 2]), valid(in[w - 1]));
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
  const bool edges = k.max_depth_jump > 0;
  const std::size_t w = static_cast<std::size_t>(k.width);
  // Kept per thread: a frame's worth of pixels, fresh memory (zeroed and page-faulted) on every frame else.
  thread_local std::vector<std::uint16_t> raw, rows;
  valid_depths(image, raw);
  if (edges && k.smoothing_radius > 0) smooth_depths(raw, k, rows);
  if (edges) nearest_in_rows(raw, k.width, k.height, rows);
  for (int v = 0; v < k.height; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    const std::uint16_t* near = edges ? &rows[row] : nullptr;
    const std::uint16_t* above = edges && v > 0 ? near - w : near;
    const std::uint16_t* below = edges && v + 1 < k.height ? near + w : near;
    for (std::size_t u = 0; u < w; ++u) {
      const std::uint16_t d = raw[row + u];
      const double z = d * k.depth_scale;
      if (d == 0 || (edges && z - std::min(std::min(above[u], near[u]), below[u]) * k.depth_scale >
                                  k.max_depth_jump * z)) {
        if (organized) points.emplace_back(nan, nan, nan);
        continue;
      }
      points.emplace_back(static_cast<float>((double(u) - k.cx) * z * inv_fx),
                          static_cast<float>((v - k.cy) * z * inv_fy), static_cast<float>(z));
    }
  }
  if (organized) {
    cloud.width = static_cast<std::uint32_t>(k.width);
    cloud.height = static_cast<std::uint32_t>(k.height);
    cloud.is_dense = false;
  } else {
    set_unorganized(cloud);
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
