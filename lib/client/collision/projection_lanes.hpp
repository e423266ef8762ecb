#pragma once
// Internal: the first alternating projections of mutual_projections.hpp, written once over a number type T:
// `double` for one box pair (signed_distance) and `Double2`, two pairs in the two halves of an SSE2 register,
// for the dense batch. Both run the same operations in the same order, so a pair gets bit-identical numbers
// whichever way it is computed. They settle most separated pairs.

#include <Eigen/Core>

#include <cmath>

#include "cellmap/collision/box_distance.hpp"
#include "cellmap/collision/obb.hpp"

namespace cellmap::collision {

/// Two doubles computed together (GCC/Clang vector extension; one SSE2 register, no -march needed).
typedef double Double2 __attribute__((vector_size(16)));

namespace projection_lanes_detail {

template <typename T>
struct LaneCount {
  static constexpr int value = 1;
};
template <>
struct LaneCount<Double2> {
  static constexpr int value = 2;
};

inline void set_lane(double* x, int, double value) {
  *x = value;
}
inline void set_lane(Double2* x, int l, double value) {
  (*x)[l] = value;
}
inline double get_lane(double x, int) {
  return x;
}
inline double get_lane(const Double2& x, int l) {
  return x[l];
}
// A comparison's outcome in lane l: bool for double, an all-ones lane for Double2.
inline bool mask_lane(int m, int) {
  return m != 0;
}
template <typename Mask>
inline bool mask_lane(const Mask& m, int l) {
  return m[l] != 0;
}

// min(max(x, -h), h) spelled as selects, which mean the same for double and vectors (no NaN inputs).
template <typename T>
inline T clamp(const T& x, const T& h) {
  const T low = -h;
  const T above = x < low ? low : x;
  return h < above ? h : above;
}

}  // namespace projection_lanes_detail

/// Boxes B, one per lane: centre, rotation (column-major: rotation[r + 3 c] = R(r, c)), half extents.
template <typename T>
struct BoxLanes final {
  static constexpr int kLanes = projection_lanes_detail::LaneCount<T>::value;
  T center[3];
  T rotation[9];
  T half[3];

  /// Puts `box` into lane l.
  void set(int l, const Obb& box) {
    using projection_lanes_detail::set_lane;
    for (int i = 0; i < 3; ++i) set_lane(&center[i], l, box.center[i]);
    for (int i = 0; i < 9; ++i) set_lane(&rotation[i], l, box.rotation.data()[i]);
    for (int i = 0; i < 3; ++i) set_lane(&half[i], l, box.half_extents[i]);
  }
};

/// Each B seen from A (A's frame): R = R_AB (column-major), t = p_AB; then A's point p, B's point q (A's
/// frame) and y (B's frame) after two rounds of projections, gap = q - p, and whether p and q are certified
/// mutually closest at a distance well above rounding.
template <typename T>
struct ProjectionLanes final {
  static constexpr int kLanes = projection_lanes_detail::LaneCount<T>::value;
  T R[9];
  T t[3];
  T p[3];
  T q[3];
  T y[3];  ///< B's point closest to p, B's coordinates: where the full iteration goes on from
  T gap[3];
  T gap2;
  T scale2;  ///< |ha|^2 + |hb|^2 + |t|^2, the scene size the tolerances scale with
  bool certified[kLanes];
};

/// B's pose in A's frame for every lane.
template <typename T>
inline void relative_poses(const Obb& a, const BoxLanes<T>& b, ProjectionLanes<T>* out) {
  const double* Ra = a.rotation.data();  // Ra[k + 3 i] = R_CA(k, i)
  const T d0 = b.center[0] - a.center[0];
  const T d1 = b.center[1] - a.center[1];
  const T d2 = b.center[2] - a.center[2];
  for (int i = 0; i < 3; ++i) out->t[i] = Ra[3 * i] * d0 + Ra[3 * i + 1] * d1 + Ra[3 * i + 2] * d2;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      out->R[i + 3 * j] = Ra[3 * i] * b.rotation[3 * j] + Ra[3 * i + 1] * b.rotation[3 * j + 1] +
                          Ra[3 * i + 2] * b.rotation[3 * j + 2];
    }
  }
}

/// From A's point closest to B's centre: y0 = B's point closest to it, p = A's point closest to q = t + R y0,
/// y = B's point closest to p. Certified when p repeats the start or y repeats y0 (to 1e-13 of the scene
/// size): then p and q are mutually closest. Needs relative_poses first.
template <typename T>
inline void project_twice(const Eigen::Vector3d& ha_, const BoxLanes<T>& b, ProjectionLanes<T>* io) {
  using projection_lanes_detail::clamp;
  const T* R = io->R;
  const T* t = io->t;
  const T ha[3] = {T{} + ha_[0], T{} + ha_[1], T{} + ha_[2]};
  T p0[3], y0[3], d[3];
  for (int i = 0; i < 3; ++i) p0[i] = clamp(t[i], ha[i]);
  for (int i = 0; i < 3; ++i) d[i] = p0[i] - t[i];
  for (int j = 0; j < 3; ++j)
    y0[j] = clamp(R[3 * j] * d[0] + R[3 * j + 1] * d[1] + R[3 * j + 2] * d[2], b.half[j]);
  for (int i = 0; i < 3; ++i) io->q[i] = t[i] + (R[i] * y0[0] + R[i + 3] * y0[1] + R[i + 6] * y0[2]);
  for (int i = 0; i < 3; ++i) io->p[i] = clamp(io->q[i], ha[i]);
  for (int i = 0; i < 3; ++i) d[i] = io->p[i] - t[i];
  for (int j = 0; j < 3; ++j) {
    io->y[j] = clamp(R[3 * j] * d[0] + R[3 * j + 1] * d[1] + R[3 * j + 2] * d[2], b.half[j]);
  }
  io->scale2 = ha_.squaredNorm() + (b.half[0] * b.half[0] + b.half[1] * b.half[1] + b.half[2] * b.half[2]) +
               (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  T moved_p = T{}, moved_y = T{}, gap2 = T{};
  for (int k = 0; k < 3; ++k) {
    moved_p += (io->p[k] - p0[k]) * (io->p[k] - p0[k]);
    moved_y += (io->y[k] - y0[k]) * (io->y[k] - y0[k]);
    io->gap[k] = io->q[k] - io->p[k];
    gap2 += io->gap[k] * io->gap[k];
  }
  io->gap2 = gap2;
  const T tolerance2 = 1e-26 * io->scale2;
  const auto certified = ((moved_p <= tolerance2) | (moved_y <= tolerance2)) & (gap2 > 1e-24 * io->scale2);
  for (int l = 0; l < ProjectionLanes<T>::kLanes; ++l) {
    io->certified[l] = projection_lanes_detail::mask_lane(certified, l);
  }
}

/// A separated pair in A's frame (p of A, q of B, gap = q - p with gap2 = |gap|^2 > 0) as the result in the
/// cell frame.
inline SignedDistance separated_in_cell(const Obb& a, const double* p, const double* q, const double* gap,
                                        double gap2) {
  const double* Ra = a.rotation.data();
  SignedDistance out;
  out.distance = std::sqrt(gap2);
  const double inverse = 1.0 / out.distance;
  const double n[3] = {gap[0] * inverse, gap[1] * inverse, gap[2] * inverse};
  for (int i = 0; i < 3; ++i) {
    out.point_a[i] = a.center[i] + (Ra[i] * p[0] + Ra[i + 3] * p[1] + Ra[i + 6] * p[2]);
    out.point_b[i] = a.center[i] + (Ra[i] * q[0] + Ra[i + 3] * q[1] + Ra[i + 6] * q[2]);
    out.normal[i] = Ra[i] * n[0] + Ra[i + 3] * n[1] + Ra[i + 6] * n[2];
  }
  return out;
}

/// Lane l of a certified projection as the separated pair's result in the cell frame.
template <typename T>
inline SignedDistance separated_lane(const Obb& a, const ProjectionLanes<T>& lanes, int l) {
  using projection_lanes_detail::get_lane;
  const double p[3] = {get_lane(lanes.p[0], l), get_lane(lanes.p[1], l), get_lane(lanes.p[2], l)};
  const double q[3] = {get_lane(lanes.q[0], l), get_lane(lanes.q[1], l), get_lane(lanes.q[2], l)};
  const double gap[3] = {get_lane(lanes.gap[0], l), get_lane(lanes.gap[1], l), get_lane(lanes.gap[2], l)};
  return separated_in_cell(a, p, q, gap, get_lane(lanes.gap2, l));
}

}  // namespace cellmap::collision
