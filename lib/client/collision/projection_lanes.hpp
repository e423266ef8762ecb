// SPDX-License-Identifier: Apache-2.0
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

// min(max(x, low), high) spelled as selects, which mean the same for double and vectors (no NaN inputs).
template <typename T>
inline T clamp(const T& x, const T& low, const T& high) {
  const T above = x < low ? low : x;
  return high < above ? high : above;
}

}  // namespace projection_lanes_detail

/// A box per lane, read in place: centre, rotation (column-major: rotation[r + 3 c] = R(r, c)), half extents.
template <typename T>
struct BoxView final {
  const T* center;
  const T* rotation;
  const T* half;
};

/// One box as a view of its own numbers.
inline BoxView<double> view_of(const Obb& box) {
  return {box.center.data(), box.rotation.data(), box.half_extents.data()};
}

/// Boxes, one per lane: centre, rotation (column-major), half extents.
template <typename T>
struct BoxLanes final {
  static constexpr int kLanes = projection_lanes_detail::LaneCount<T>::value;
  T center[3] = {};
  T rotation[9] = {};
  T half[3] = {};

  /// Puts `box` into lane l.
  void set(int l, const Obb& box) {
    using projection_lanes_detail::set_lane;
    for (int i = 0; i < 3; ++i) set_lane(&center[i], l, box.center[i]);
    for (int i = 0; i < 9; ++i) set_lane(&rotation[i], l, box.rotation.data()[i]);
    for (int i = 0; i < 3; ++i) set_lane(&half[i], l, box.half_extents[i]);
  }
  /// `box` in every lane.
  static BoxLanes broadcast(const Obb& box) {
    BoxLanes lanes;
    for (int i = 0; i < 3; ++i) lanes.center[i] = T{} + box.center[i];
    for (int i = 0; i < 9; ++i) lanes.rotation[i] = T{} + box.rotation.data()[i];
    for (int i = 0; i < 3; ++i) lanes.half[i] = T{} + box.half_extents[i];
    return lanes;
  }
  [[nodiscard]] BoxView<T> view() const { return {center, rotation, half}; }
};

/// Each B seen from A (A's frame): R = R_AB (column-major), t = p_AB; then A's point p and B's point
/// q = p + gap after two rounds of projections, and whether they are certified mutually closest at a distance
/// well above rounding.
template <typename T>
struct ProjectionLanes final {
  static constexpr int kLanes = projection_lanes_detail::LaneCount<T>::value;
  T R[9];
  T t[3];
  T p[3];
  T y[3];  ///< B's point closest to p, B's coordinates: where the full iteration goes on from
  T gap[3];
  T gap2;
  T scale2;  ///< |ha|^2 + |hb|^2 + |t|^2, the scene size the tolerances scale with
  bool certified[kLanes];
};

/// Box A against box B in every lane (A may be the same box in every lane): B's pose in A's frame, then from
/// A's point closest to B's centre: y0 = B's point closest to it, p = A's point closest to q = t + R y0, y =
/// B's point closest to p. Certified when p repeats the start or y repeats y0 (to 1e-13 of the scene size):
/// then p and q are mutually closest.
template <typename T>
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline void
project_twice(const BoxView<T>& a, const BoxView<T>& b, ProjectionLanes<T>* io) {
  using projection_lanes_detail::clamp;
  const T* Ra = a.rotation;  // Ra[k + 3 i] = R_CA(k, i)
  const T* ha = a.half;
  const T* half_b = b.half;
  T* R = io->R;
  T* t = io->t;
  const T d_C[3] = {b.center[0] - a.center[0], b.center[1] - a.center[1], b.center[2] - a.center[2]};
  for (int i = 0; i < 3; ++i) t[i] = Ra[3 * i] * d_C[0] + Ra[3 * i + 1] * d_C[1] + Ra[3 * i + 2] * d_C[2];
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      R[i + 3 * j] = Ra[3 * i] * b.rotation[3 * j] + Ra[3 * i + 1] * b.rotation[3 * j + 1] +
                     Ra[3 * i + 2] * b.rotation[3 * j + 2];
    }
  }
  const T low_a[3] = {-ha[0], -ha[1], -ha[2]};
  const T low_b[3] = {-half_b[0], -half_b[1], -half_b[2]};
  T p0[3], y0[3], q[3], d[3];
  for (int i = 0; i < 3; ++i) p0[i] = clamp(t[i], low_a[i], ha[i]);
  for (int i = 0; i < 3; ++i) d[i] = p0[i] - t[i];
  for (int j = 0; j < 3; ++j) {
    y0[j] = clamp(R[3 * j] * d[0] + R[3 * j + 1] * d[1] + R[3 * j + 2] * d[2], low_b[j], half_b[j]);
  }
  for (int i = 0; i < 3; ++i) q[i] = t[i] + (R[i] * y0[0] + R[i + 3] * y0[1] + R[i + 6] * y0[2]);
  for (int i = 0; i < 3; ++i) io->p[i] = clamp(q[i], low_a[i], ha[i]);
  for (int i = 0; i < 3; ++i) d[i] = io->p[i] - t[i];
  for (int j = 0; j < 3; ++j) {
    io->y[j] = clamp(R[3 * j] * d[0] + R[3 * j + 1] * d[1] + R[3 * j + 2] * d[2], low_b[j], half_b[j]);
  }
  io->scale2 = (ha[0] * ha[0] + ha[1] * ha[1] + ha[2] * ha[2]) +
               (half_b[0] * half_b[0] + half_b[1] * half_b[1] + half_b[2] * half_b[2]) +
               (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  T moved_p = T{}, moved_y = T{}, gap2 = T{};
  for (int k = 0; k < 3; ++k) {
    moved_p += (io->p[k] - p0[k]) * (io->p[k] - p0[k]);
    moved_y += (io->y[k] - y0[k]) * (io->y[k] - y0[k]);
    io->gap[k] = q[k] - io->p[k];
    gap2 += io->gap[k] * io->gap[k];
  }
  io->gap2 = gap2;
  const T tolerance2 = 1e-26 * io->scale2;
  // Nearer pairs (1e-3 of the scene size) need the check of signed_distance.cpp's certified_apart.
  const auto certified = ((moved_p <= tolerance2) | (moved_y <= tolerance2)) & (gap2 > 1e-6 * io->scale2);
  for (int l = 0; l < ProjectionLanes<T>::kLanes; ++l) {
    io->certified[l] = projection_lanes_detail::mask_lane(certified, l);
  }
}

/// Separated pairs in A's frame (p of A, q = p + gap of B, gap2 = |gap|^2 > 0) as results in the cell frame:
/// the distance, point_a, point_b = point_a + the gap, and the unit normal.
template <typename T>
struct SeparatedLanes final {
  T distance;
  T point_a[3];
  T point_b[3];
  T normal[3];

  SeparatedLanes(const BoxView<T>& a, const T* p, const T* gap, const T& gap2) {
    using namespace projection_lanes_detail;
    distance = T{};
    for (int l = 0; l < LaneCount<T>::value; ++l) set_lane(&distance, l, std::sqrt(get_lane(gap2, l)));
    // 1 / distance as distance / gap2: the division runs beside the square root instead of after it.
    const T inverse = distance * (1.0 / gap2);
    const T* Ra = a.rotation;
    for (int i = 0; i < 3; ++i) {
      const T gap_C = Ra[i] * gap[0] + Ra[i + 3] * gap[1] + Ra[i + 6] * gap[2];
      point_a[i] = a.center[i] + (Ra[i] * p[0] + Ra[i + 3] * p[1] + Ra[i + 6] * p[2]);
      point_b[i] = point_a[i] + gap_C;
      normal[i] = gap_C * inverse;
    }
  }

  /// Lane l as a SignedDistance.
  [[nodiscard]] SignedDistance lane(int l) const {
    using projection_lanes_detail::get_lane;
    SignedDistance out;
    out.distance = get_lane(distance, l);
    for (int i = 0; i < 3; ++i) {
      out.point_a[i] = get_lane(point_a[i], l);
      out.point_b[i] = get_lane(point_b[i], l);
      out.normal[i] = get_lane(normal[i], l);
    }
    return out;
  }
};

/// A separated pair in A's frame as the result in the cell frame (see SeparatedLanes).
inline SignedDistance separated_in_cell(const Obb& a, const double* p, const double* gap, double gap2) {
  return SeparatedLanes<double>(view_of(a), p, gap, gap2).lane(0);
}

}  // namespace cellmap::collision
