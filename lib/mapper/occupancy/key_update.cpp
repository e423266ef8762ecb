// SPDX-License-Identifier: Apache-2.0
#include "key_update.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "cellmap/common/error.hpp"
#include "cellmap/common/parallel.hpp"

// Written here rather than taken from OctoMap: OcTree::insertPointCloud walks every ray into a per-ray KeyRay
// and inserts every step into an unordered_set (about 1 s per 640×480 frame at 2 cm); this walks one ray per
// distinct endpoint voxel and marks its steps in a bit set laid out in tree-aligned bricks, on several
// threads.

namespace cellmap {
namespace {

using Key = octomap::OcTreeKey;

// An axis-aligned box of keys (inclusive bounds) with a dense index, x fastest.
struct KeyBox {
  int lo[3] = {std::numeric_limits<int>::max(), std::numeric_limits<int>::max(),
               std::numeric_limits<int>::max()};
  int hi[3] = {-1, -1, -1};

  void extend(const Key& k) {
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], int{k[i]});
      hi[i] = std::max(hi[i], int{k[i]});
    }
  }
  void extend(const KeyBox& other) {
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], other.lo[i]);
      hi[i] = std::max(hi[i], other.hi[i]);
    }
  }
  // One voxel of slack on each side: a ray walk never leaves the box of its end voxels, but rounding at voxel
  // corners may step one voxel aside before it stops.
  void grow() {
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::max(lo[i] - 1, 0);
      hi[i] = std::min(hi[i] + 1, 0xffff);
    }
  }
  [[nodiscard]] bool empty() const { return hi[0] < lo[0]; }
  [[nodiscard]] std::uint64_t size(int i) const { return static_cast<std::uint64_t>(hi[i] - lo[i] + 1); }
  [[nodiscard]] std::uint64_t volume() const { return empty() ? 0 : size(0) * size(1) * size(2); }
};

// The dense index of packed keys in a KeyBox (x fastest), with its strides held in registers.
class BoxIndex {
 public:
  explicit BoxIndex(const KeyBox& box)
      : stride_y_(box.size(0)),
        stride_z_(box.size(0) * box.size(1)),
        first_(std::uint64_t(box.lo[0]) + std::uint64_t(box.lo[1]) * stride_y_ +
               std::uint64_t(box.lo[2]) * stride_z_) {}
  [[nodiscard]] std::uint64_t operator()(std::uint64_t packed) const {
    return (packed & 0xffff) + ((packed >> 16) & 0xffff) * stride_y_ + (packed >> 32) * stride_z_ - first_;
  }

 private:
  std::uint64_t stride_y_, stride_z_, first_;
};

// Boxes larger than this fall back to sorting packed keys (a 2^28-bit set is 32 MB).
constexpr std::uint64_t kMaxDenseVoxels = std::uint64_t{1} << 28;
constexpr int kBrickWords = KeyBrick::kVoxels / 64;

// Spreads the 4 bits of v to bits 0, 3, 6, 9.
constexpr std::array<std::uint16_t, 16> kSpread4 = [] {
  std::array<std::uint16_t, 16> table{};
  for (int v = 0; v < 16; ++v) {
    int out = 0;
    for (int b = 0; b < 4; ++b) out |= ((v >> b) & 1) << (3 * b);
    table[std::size_t(v)] = static_cast<std::uint16_t>(out);
  }
  return table;
}();

// The 48-bit interleave of a key (x lowest in each triple): the OcTree's depth-first order.
std::uint64_t morton(const Key& k) {
  std::uint64_t out = 0;
  for (int b = 0; b < 16; ++b) {
    for (int axis = 0; axis < 3; ++axis) out |= std::uint64_t((k[axis] >> b) & 1) << (3 * b + axis);
  }
  return out;
}

Key brick_base(const Key& k) {
  return Key(static_cast<std::uint16_t>(k[0] & ~0xf), static_cast<std::uint16_t>(k[1] & ~0xf),
             static_cast<std::uint16_t>(k[2] & ~0xf));
}

// The bricks of a key box (aligned outwards to whole bricks) as one dense bit array: brick after brick in
// (z, y, x) order, each brick's 4096 bits in KeyBrick order. The index is separable, offset[0][x] +
// offset[1][y] + offset[2][z], so that a ray walk step (one axis) costs one table lookup. Each table has one
// guard entry more on either side of the box holding kOutside: a sum with it is at least bits(), so a walk
// that steps out of the box sees an index past the end instead of reading or writing outside.
struct BrickGrid {
  static constexpr std::uint32_t kOutside = std::uint32_t{1} << 30;  // > 3 × 2^28: no sum wraps
  int lo[3];                                                         // key of the first brick's base
  int count[3];                                                      // bricks per axis
  std::vector<std::uint32_t> offset[3];

  explicit BrickGrid(const KeyBox& box) {
    for (int i = 0; i < 3; ++i) {
      lo[i] = box.lo[i] & ~0xf;
      count[i] = ((box.hi[i] | 0xf) - lo[i] + 1) / KeyBrick::kEdge;
    }
    if (!dense()) return;  // sparse: no tables
    const std::uint64_t stride[3] = {KeyBrick::kVoxels, std::uint64_t(count[0]) * KeyBrick::kVoxels,
                                     std::uint64_t(count[0]) * count[1] * KeyBrick::kVoxels};
    for (int i = 0; i < 3; ++i) {
      const std::size_t size = std::size_t(count[i]) * KeyBrick::kEdge;
      offset[i].assign(size + 2, kOutside);
      for (std::size_t v = 0; v < size; ++v) {
        offset[i][v + 1] =
            static_cast<std::uint32_t>((v >> 4) * stride[i] + (std::uint64_t(kSpread4[v & 0xf]) << i));
      }
    }
  }
  [[nodiscard]] bool dense() const { return bits() <= kMaxDenseVoxels; }
  // Table position of key component `k` on `axis` (0 and size + 1 are the guards).
  [[nodiscard]] std::size_t slot(int axis, int k) const {
    return std::size_t(std::clamp(k - lo[axis] + 1, 0, int(offset[axis].size()) - 1));
  }
  // Bit index of a key (dense grids only), bits() or more outside the box.
  [[nodiscard]] std::uint32_t index(const Key& k) const {
    return offset[0][slot(0, k[0])] + offset[1][slot(1, k[1])] + offset[2][slot(2, k[2])];
  }
  [[nodiscard]] std::uint64_t bricks() const { return std::uint64_t(count[0]) * count[1] * count[2]; }
  [[nodiscard]] std::uint64_t bits() const { return bricks() * KeyBrick::kVoxels; }
  [[nodiscard]] Key brick_base(std::uint64_t brick) const {
    const std::uint64_t bx = brick % count[0];
    const std::uint64_t byz = brick / count[0];
    return Key(static_cast<std::uint16_t>(lo[0] + 16 * bx),
               static_cast<std::uint16_t>(lo[1] + 16 * (byz % count[1])),
               static_cast<std::uint16_t>(lo[2] + 16 * (byz / count[1])));
  }
};

// Walk position in a dense BrickGrid: per axis a pointer into its offset table and the entry it points at;
// the bit index is the sum of the three entries. A walk copies its cursor, so that this state lives in
// registers.
class DenseCursor {
 public:
  DenseCursor(const BrickGrid& grid, std::uint64_t* words) : grid_(grid), words_(words), bits_(grid.bits()) {}
  // Starts at `from`, the walk ending at `to` and moving by `step` (-1, 0 or +1 per axis); false if `from` is
  // outside the grid.
  bool start(const Key& from, const Key& to, const int step[3]) {
    for (int i = 0; i < 3; ++i) {
      at_[i] = grid_.offset[i].data() + grid_.slot(i, from[i]);
      entry_[i] = *at_[i];
      step_[i] = step[i];
    }
    index_ = entry_[0] + entry_[1] + entry_[2];
    end_ = grid_.index(to);
    return index_ < bits_;
  }
  template <int kAxis>
  void step() {
    at_[kAxis] += step_[kAxis];
    entry_[kAxis] = *at_[kAxis];
    index_ = entry_[0] + entry_[1] + entry_[2];
  }
  // At the end voxel, or out of the grid (one test: a guard entry makes the index ≥ bits).
  [[nodiscard]] bool done() const { return (index_ == end_) | outside(); }
  [[nodiscard]] bool outside() const { return index_ >= bits_; }
  void mark() { words_[index_ >> 6] |= std::uint64_t{1} << (index_ & 63); }

 private:
  const BrickGrid& grid_;
  std::uint64_t* words_;
  std::uint32_t bits_;
  const std::uint32_t* at_[3] = {nullptr, nullptr, nullptr};
  std::uint32_t entry_[3] = {0, 0, 0};
  int step_[3] = {0, 0, 0};
  std::uint32_t index_ = 0, end_ = 0;
};

// Walk position that lists packed keys (for boxes too large for a dense bit array).
class SparseCursor {
 public:
  explicit SparseCursor(std::vector<std::uint64_t>& out) : out_(&out) {}
  bool start(const Key& from, const Key& to, const int step[3]) {
    for (int i = 0; i < 3; ++i) {
      key_[i] = from[i];
      end_[i] = to[i];
      step_[i] = step[i];
    }
    return true;
  }
  template <int kAxis>
  void step() {
    key_[kAxis] += step_[kAxis];
  }
  [[nodiscard]] bool done() const {
    return (key_[0] == end_[0] && key_[1] == end_[1] && key_[2] == end_[2]) || outside();
  }
  [[nodiscard]] bool outside() const { return ((key_[0] | key_[1] | key_[2]) & ~0xffff) != 0; }
  void mark() {
    out_->push_back(std::uint64_t(key_[0]) | (std::uint64_t(key_[1]) << 16) | (std::uint64_t(key_[2]) << 32));
  }

 private:
  std::vector<std::uint64_t>* out_;
  int key_[3] = {0, 0, 0};
  int end_[3] = {0, 0, 0};
  int step_[3] = {0, 0, 0};
};

void set_bit(std::vector<std::uint64_t>& words, std::uint64_t i) {
  words[i >> 6] |= std::uint64_t{1} << (i & 63);
}

void sort_depth_first(std::vector<KeyBrick>& bricks) {
  std::sort(bricks.begin(), bricks.end(),
            [](const KeyBrick& a, const KeyBrick& b) { return morton(a.base) < morton(b.base); });
}

std::vector<std::uint64_t> sorted_unique(std::vector<std::uint64_t> packed) {
  std::sort(packed.begin(), packed.end());
  packed.erase(std::unique(packed.begin(), packed.end()), packed.end());
  return packed;
}

class BitSet {
 public:
  explicit BitSet(std::uint64_t bits) : words_((bits + 63) / 64, 0) {}
  // Returns whether the bit was already set.
  bool test_and_set(std::uint64_t i) {
    std::uint64_t& word = words_[i >> 6];
    const std::uint64_t mask = std::uint64_t{1} << (i & 63);
    const bool was = (word & mask) != 0;
    word |= mask;
    return was;
  }

 private:
  std::vector<std::uint64_t> words_;
};

std::vector<Key> keys_of(const std::vector<KeyBrick>& bricks, bool occupied) {
  std::vector<std::uint64_t> packed;
  for (const KeyBrick& brick : bricks) {
    const auto& words = occupied ? brick.occupied : brick.free;
    for (int w = 0; w < kBrickWords; ++w) {
      for (std::uint64_t word = words[std::size_t(w)]; word != 0; word &= word - 1) {
        const Key k = brick.key(w * 64 + __builtin_ctzll(word));
        packed.push_back(std::uint64_t{k[0]} | (std::uint64_t{k[1]} << 16) | (std::uint64_t{k[2]} << 32));
      }
    }
  }
  std::sort(packed.begin(), packed.end());  // z:y:x packing sorts by (z, y, x)
  std::vector<Key> out;
  out.reserve(packed.size());
  for (const std::uint64_t p : packed) out.push_back(unpack_key(p));
  return out;
}

// The sensor origin of one scan, as OctoMap sees it (single precision).
struct Origin {
  float p[3];
  Key key;
};

// One ray: from its scan's origin to `end` (a voxel centre, or the max-range point of a farther one).
struct Ray {
  float end[3];
  Key end_key;
  bool cut;  // ends at max_range, not at a voxel centre
  std::uint32_t origin;
};

// The per-axis state of a walk from `origin` towards `ray`'s end, with OctoMap's computeRayKeys arithmetic:
// single-precision direction, double-precision crossing distances (an axis the ray does not move along
// never comes first).
struct WalkStart {
  float length;       // distance from the origin to the ray's end
  int step[3];        // -1, 0 or +1 key per crossing
  double t_max[3];    // distance to the first crossing
  double t_delta[3];  // distance between crossings
};

WalkStart walk_start(const Origin& origin, const Ray& ray, const octomap::OcTree& grid) {
  const double resolution = grid.getResolution();
  WalkStart w{};
  float direction[3] = {ray.end[0] - origin.p[0], ray.end[1] - origin.p[1], ray.end[2] - origin.p[2]};
  const float norm_sq =
      direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2];
  w.length = static_cast<float>(std::sqrt(static_cast<double>(norm_sq)));
  for (float& d : direction) d /= w.length;
  for (int i = 0; i < 3; ++i) {
    w.step[i] = direction[i] > 0.0f ? 1 : (direction[i] < 0.0f ? -1 : 0);
    if (w.step[i] != 0) {
      double border = grid.keyToCoord(origin.key[i]);
      border += static_cast<float>(w.step[i] * resolution * 0.5);
      w.t_max[i] = (border - origin.p[i]) / direction[i];
      w.t_delta[i] = resolution / std::fabs(direction[i]);
    } else {
      w.t_max[i] = std::numeric_limits<double>::max();
      w.t_delta[i] = std::numeric_limits<double>::max();
    }
  }
  return w;
}

// Amanatides & Woo's voxel walk, in key space. It follows OctoMap's computeRayKeys arithmetic (walk_start,
// the same tie-breaking between axes and the same stop rule) so that the crossed voxels match OctoMap's, but
// it hands each voxel to `cursor` (a copy, kept in registers) instead of storing the ray. The origin voxel is
// included, the end voxel is not; a ray within one voxel marks nothing. The walk stops where it leaves the
// cursor's grid (it never comes back on that axis). A ray to a voxel centre (kToCentre) needs no end-voxel
// test: in its end voxel every next crossing lies at least half a voxel past the centre, so the length test
// stops it there (rounding errors are below a micrometre).
template <bool kToCentre, class Cursor>
void walk_ray(const Origin& origin, const Ray& ray, const octomap::OcTree& grid, Cursor cursor) {
  if (origin.key == ray.end_key) return;
  const WalkStart w = walk_start(origin, ray, grid);
  if (!cursor.start(origin.key, ray.end_key, w.step)) return;
  cursor.mark();
  double tx = w.t_max[0], ty = w.t_max[1], tz = w.t_max[2];
  const double dx = w.t_delta[0], dy = w.t_delta[1], dz = w.t_delta[2];
  const double length = w.length;
  // OctoMap steps along the axis of the nearest crossing, stops at the end voxel, then stops if the next
  // crossing lies past the end point (rounding at a corner), and else marks the voxel. Here each turn tests
  // the next crossing, marks the voxel the previous step entered (the origin voxel, marked already, on the
  // first turn), then steps: the same rule (if the first crossing lies past the end point, OctoMap takes the
  // first step, then stops without marking). Each axis has its own code path: the choice is a branch, which
  // lets the next step start before the comparison ends (a branch-free choice measured slower: every step
  // then waits for the comparison). The walk ends: every step moves one voxel, and the cursor's grid is
  // finite (it stops where the walk leaves it), as is the length (every crossing distance grows by its
  // positive delta at its step).
  auto advance = [&](double& t, double delta, auto axis) {
    if (t > length) return false;
    cursor.mark();
    t += delta;
    cursor.template step<decltype(axis)::value>();
    return !(kToCentre ? cursor.outside() : cursor.done());
  };
  using X = std::integral_constant<int, 0>;
  using Y = std::integral_constant<int, 1>;
  using Z = std::integral_constant<int, 2>;
  // OctoMap's tie-breaking: the later axis wins ties. Each branch leaves on its own test, so that the test
  // is one compare and jump.
  for (;;) {
    if (tx < ty) {
      if (tx < tz) {
        if (!advance(tx, dx, X{})) return;
      } else if (!advance(tz, dz, Z{})) {
        return;
      }
    } else if (ty < tz) {
      if (!advance(ty, dy, Y{})) return;
    } else if (!advance(tz, dz, Z{})) {
      return;
    }
  }
}

// Walks `ray`, with the end-voxel test only where it is needed (a ray cut at max_range).
template <class Cursor>
void walk(const Origin& origin, const Ray& ray, const octomap::OcTree& grid, const Cursor& cursor) {
  if (ray.cut) {
    walk_ray<false>(origin, ray, grid, cursor);
  } else {
    walk_ray<true>(origin, ray, grid, cursor);
  }
}

constexpr std::uint64_t kNoKey = ~std::uint64_t{0};

// OctoMap's coordToKeyChecked arithmetic, inlined (it is out of line in the library): key = floor(x /
// resolution) + the tree's key offset. Branch-free, so that a run of points costs the same whether or not
// neighbouring points share a voxel (a branch on that is mispredicted at every voxel border).
class KeyConverter {
 public:
  explicit KeyConverter(const octomap::OcTree& grid)
      : factor_(1.0 / grid.getResolution()), max_val_(int(grid.coordToKey(0.0))) {}

  // The packed key of (x, y, z), or kNoKey if a coordinate is not finite or outside the key range.
  [[nodiscard]] std::uint64_t key(float x, float y, float z) const {
    const double scaled[3] = {factor_ * double(x), factor_ * double(y), factor_ * double(z)};
    const double max_val = max_val_;
    bool inside = true;
    std::uint64_t packed = 0;
    for (int i = 0; i < 3; ++i) {
      // floor(s) is in [-max_val, max_val) exactly when s is (max_val is an integer); NaN and infinity fail.
      const bool in_range = (scaled[i] >= -max_val) & (scaled[i] < max_val);
      inside &= in_range;
      const double s = in_range ? scaled[i] : 0.0;  // keeps the conversion defined
      const int truncated = int(s);
      const int floored = truncated - (double(truncated) > s);  // floor, without a libm call
      packed |= std::uint64_t(std::uint32_t(floored + max_val_) & 0xffff) << (16 * i);
    }
    return inside ? packed : kNoKey;
  }

  // Points read ahead into the cache: a frame's points are read once, from memory, and waiting for them was
  // most of the key conversion's time (grabber frames, 2 threads: 10.2–11.1 → 7.6–7.8 ms per fusion of the
  // 3 frames; 256 or 1 024 points ahead measured 7.9–8.0).
  static constexpr std::size_t kPrefetchAhead = 512;
  // out[i] = key(p[i].x, p[i].y, p[i].z) for i < count, bit for bit; `redo` has room for `count` indices.
  void keys(const pcl::PointXYZ* p, std::size_t count, std::uint64_t* out, std::uint32_t* redo) const {
    std::size_t i = 0;
#if defined(__SSE2__)
    std::size_t redo_count = 0;
    for (; i + 4 <= count; i += 4) {
      // Integer arithmetic: the address may lie past the points (a prefetch never faults).
      _mm_prefetch(reinterpret_cast<const char*>(reinterpret_cast<std::uintptr_t>(p + i) +
                                                 kPrefetchAhead * sizeof(pcl::PointXYZ)),
                   _MM_HINT_T0);
      redo_count = four_keys(p, i, out, redo, redo_count);
    }
    for (std::size_t r = 0; r < redo_count; ++r) out[redo[r]] = key(p[redo[r]].x, p[redo[r]].y, p[redo[r]].z);
#else
    (void)redo;
#endif
    for (; i < count; ++i) out[i] = key(p[i].x, p[i].y, p[i].z);
  }

 private:
#if defined(__SSE2__)
  // Points i .. i + 3 at once in single precision (four lanes per instruction instead of two): u = x ×
  // factor + 32768 differs from OctoMap's double x × factor + 32768 by less than 2^-8 + 2^-9 inside the key
  // range (rounding of the factor, the product and the sum), so trunc(u), which is floor(u) for u ≥ 0, is
  // OctoMap's key unless an integer lies within 2^-7 of u. The indices of points with such a coordinate
  // (about 8 %: depths in whole millimetres often put z × 50 next to an integer) are appended to `redo`
  // without a branch, to be redone with key(); returns the new count.
  std::size_t four_keys(const pcl::PointXYZ* p, std::size_t i, std::uint64_t* out, std::uint32_t* redo,
                        std::size_t redo_count) const {
    const __m128 p0 = _mm_loadu_ps(p[i].data), p1 = _mm_loadu_ps(p[i + 1].data);
    const __m128 p2 = _mm_loadu_ps(p[i + 2].data), p3 = _mm_loadu_ps(p[i + 3].data);
    const __m128 xy01 = _mm_unpacklo_ps(p0, p1), xy23 = _mm_unpacklo_ps(p2, p3);  // x0 x1 y0 y1, x2 x3 y2 y3
    const __m128 z01 = _mm_unpackhi_ps(p0, p1), z23 = _mm_unpackhi_ps(p2, p3);    // z0 z1 _ _, z2 z3 _ _
    __m128 near = _mm_setzero_ps();
    __m128 inside = _mm_castsi128_ps(_mm_set1_epi32(-1));
    const __m128i kx = axis_keys(_mm_movelh_ps(xy01, xy23), near, inside);
    const __m128i ky = axis_keys(_mm_movehl_ps(xy23, xy01), near, inside);
    const __m128i kz = axis_keys(_mm_movelh_ps(z01, z23), near, inside);
    const __m128i xy = _mm_or_si128(kx, _mm_slli_epi32(ky, 16));
    const __m128i outside = _mm_xor_si128(_mm_castps_si128(inside), _mm_set1_epi32(-1));
    // Packed z:y:x per point; an outside point's key is all ones (kNoKey).
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i),
                     _mm_or_si128(_mm_unpacklo_epi32(xy, kz), _mm_unpacklo_epi32(outside, outside)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i + 2),
                     _mm_or_si128(_mm_unpackhi_epi32(xy, kz), _mm_unpackhi_epi32(outside, outside)));
    // The near lanes' indices, in order, with one store (its lanes past the near ones are overwritten later
    // or ignored: redo_count + 3 < count, as redo_count <= i).
    const int lanes = _mm_movemask_ps(near);
    const __m128i order = _mm_loadu_si128(reinterpret_cast<const __m128i*>(kSetLanes[lanes].data()));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(redo + redo_count),
                     _mm_add_epi32(order, _mm_set1_epi32(static_cast<int>(i))));
    return redo_count + std::size_t(kSetLanes[lanes][4]);
  }

  // For each 4-bit lane mask: the set lanes in increasing order, then (entry 4) how many there are.
  static constexpr std::array<std::array<std::uint32_t, 5>, 16> kSetLanes = [] {
    std::array<std::array<std::uint32_t, 5>, 16> table{};
    for (std::uint32_t mask = 0; mask < 16; ++mask) {
      std::uint32_t count = 0;
      for (std::uint32_t lane = 0; lane < 4; ++lane) {
        if ((mask >> lane) & 1) table[mask][count++] = lane;
      }
      table[mask][4] = count;
    }
    return table;
  }();

  // trunc(v × factor + 32768) of four coordinates (the key where `inside` and not `near`); clears `inside`
  // where out of the key range (or not finite) and sets `near` where single precision may be off by one.
  __m128i axis_keys(__m128 v, __m128& near, __m128& inside) const {
    const __m128 offset = _mm_set1_ps(float(max_val_));
    const __m128 tolerance = _mm_set1_ps(0x1p-7f);
    const __m128 u = _mm_add_ps(_mm_mul_ps(v, _mm_set1_ps(float(factor_))), offset);
    const __m128i truncated = _mm_cvttps_epi32(u);
    const __m128 fraction = _mm_sub_ps(u, _mm_cvtepi32_ps(truncated));  // exact
    near = _mm_or_ps(near, _mm_or_ps(_mm_cmple_ps(fraction, tolerance),
                                     _mm_cmpge_ps(fraction, _mm_sub_ps(_mm_set1_ps(1.0f), tolerance))));
    inside = _mm_and_ps(
        inside, _mm_and_ps(_mm_cmpge_ps(u, _mm_setzero_ps()), _mm_cmplt_ps(u, _mm_add_ps(offset, offset))));
    return truncated;
  }
#endif

  double factor_;
  int max_val_;
};

// Extends `box` by the packed keys keys[0 .. n): per component their least and greatest value, two keys per
// instruction where SSE2 is there (16-bit lanes; SSE2 compares them signed, hence the flip of the top bit).
void extend_by_packed(KeyBox& box, const std::uint64_t* keys, std::size_t n) {
#if defined(__SSE2__)
  if (n == 0) return;
  const __m128i flip = _mm_set1_epi16(static_cast<short>(0x8000));
  __m128i least = _mm_set1_epi16(0x7fff);
  __m128i greatest = _mm_set1_epi16(static_cast<short>(0x8000));
  const auto take = [&](__m128i two_keys) {
    two_keys = _mm_xor_si128(two_keys, flip);
    least = _mm_min_epi16(least, two_keys);
    greatest = _mm_max_epi16(greatest, two_keys);
  };
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) take(_mm_loadu_si128(reinterpret_cast<const __m128i*>(keys + i)));
  if (i < n) {
    const __m128i last = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(keys + i));
    take(_mm_unpacklo_epi64(last, last));
  }
  least = _mm_min_epi16(least, _mm_shuffle_epi32(least, _MM_SHUFFLE(1, 0, 3, 2)));
  greatest = _mm_max_epi16(greatest, _mm_shuffle_epi32(greatest, _MM_SHUFFLE(1, 0, 3, 2)));
  least = _mm_xor_si128(least, flip);
  greatest = _mm_xor_si128(greatest, flip);
  box.extend(Key(static_cast<std::uint16_t>(_mm_extract_epi16(least, 0)),
                 static_cast<std::uint16_t>(_mm_extract_epi16(least, 1)),
                 static_cast<std::uint16_t>(_mm_extract_epi16(least, 2))));
  box.extend(Key(static_cast<std::uint16_t>(_mm_extract_epi16(greatest, 0)),
                 static_cast<std::uint16_t>(_mm_extract_epi16(greatest, 1)),
                 static_cast<std::uint16_t>(_mm_extract_epi16(greatest, 2))));
#else
  for (std::size_t i = 0; i < n; ++i) box.extend(unpack_key(keys[i]));
#endif
}

// Appends to `keys` the packed keys of `points` [begin, end), skipping invalid points and repeats of the
// previous point's key (neighbouring pixels mostly share a voxel), and extends `box` by them. Converts and
// compacts block by block through a small buffer, so that no frame-sized memory is written twice.
void append_point_keys(const std::vector<pcl::PointXYZ, Eigen::aligned_allocator<pcl::PointXYZ>>& points,
                       std::size_t begin, std::size_t end, const KeyConverter& converter,
                       std::vector<std::uint64_t>& keys, KeyBox& box) {
  constexpr std::size_t kBlock = 256;
  std::uint64_t block[kBlock];
  std::uint32_t redo[kBlock];
  std::uint64_t last = kNoKey;
  for (std::size_t block_begin = begin; block_begin < end; block_begin += kBlock) {
    const std::size_t count = std::min(end - block_begin, kBlock);
    converter.keys(points.data() + block_begin, count, block, redo);
    std::size_t n = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint64_t packed = block[i];
      block[n] = packed;  // n <= i: compacts in place
      n += std::size_t((packed != last) & (packed != kNoKey));
      last = packed;
    }
    extend_by_packed(box, block, n);
    keys.insert(keys.end(), block, block + n);
  }
}

enum class RayEnd { kVoxel, kCut, kOutside };

// The ray from `origin` to the centre of voxel `end` (kVoxel); one that ends farther than `max_range` is cut
// there (kCut: its end voxel is then neither hit nor cleared), or dropped if the cut end lies outside the map
// (kOutside).
RayEnd ray_to(const octomap::OcTree& grid, const Origin& origin, const Key& end, double max_range, Ray& ray) {
  const octomap::point3d centre = grid.keyToCoord(end);
  float offset[3];
  float norm_sq = 0.0f;
  for (int i = 0; i < 3; ++i) {
    offset[i] = centre(i) - origin.p[i];
    norm_sq += offset[i] * offset[i];
  }
  const double distance = std::sqrt(static_cast<double>(norm_sq));
  if (distance <= max_range) {
    for (int i = 0; i < 3; ++i) ray.end[i] = centre(i);
    ray.end_key = end;
    return RayEnd::kVoxel;
  }
  // Same rounding as OctoMap: normalize in single precision, then scale.
  for (int i = 0; i < 3; ++i) {
    ray.end[i] = origin.p[i] + (offset[i] / static_cast<float>(distance)) * static_cast<float>(max_range);
  }
  return grid.coordToKeyChecked(ray.end[0], ray.end[1], ray.end[2], ray.end_key) ? RayEnd::kCut
                                                                                 : RayEnd::kOutside;
}

// The rays one thread made from its share of a scan's points and clear-only ray ends: one to each distinct
// voxel of its share, the hits among their ends, and the key box of the ends. A voxel that points of two
// shares hold gets a ray from each: the same ray, which marks the same voxels twice.
struct RayShare {
  std::vector<Ray> rays;
  std::vector<Key> hits;
  KeyBox box;
};

// The packed keys of one share: its points' (consecutive repeats dropped) and its clear-only ray ends', with
// the box of all of them.
struct ShareKeys {
  std::vector<std::uint64_t> points, clear;
  KeyBox box;
};

// The distinct keys of `keys`, points first, then the clear-only ends that hold no point (a bit set over
// their box, or sorting when the box is huge), passed to take(packed, is_point).
template <class Take>
void for_each_distinct(const ShareKeys& keys, const Take& take) {
  if (keys.box.volume() > kMaxDenseVoxels) {
    const std::vector<std::uint64_t> points = sorted_unique(keys.points);
    for (const std::uint64_t p : points) take(p, true);
    for (const std::uint64_t p : sorted_unique(keys.clear)) {
      if (!std::binary_search(points.begin(), points.end(), p)) take(p, false);
    }
    return;
  }
  BitSet seen(keys.box.volume());
  const BoxIndex index(keys.box);
  for (const std::uint64_t p : keys.points) {
    if (!seen.test_and_set(index(p))) take(p, true);
  }
  for (const std::uint64_t p : keys.clear) {
    if (!seen.test_and_set(index(p))) take(p, false);
  }
}

// The rays of one share from `origin` (scan `s`): one to each distinct voxel of `keys`; those of points
// within range are hits.
RayShare share_rays(const ShareKeys& keys, const octomap::OcTree& grid, double max_range,
                    const Origin& origin, std::uint32_t s) {
  RayShare out;
  // At most one ray per key: reserved at once, so that no ray is copied as the list grows (pages past the
  // rays made are never touched; without it, grabber fusion measured up to 10 % slower).
  out.rays.reserve(keys.points.size() + keys.clear.size());
  for_each_distinct(keys, [&](std::uint64_t packed, bool point) {
    Ray ray{};
    const Key key = unpack_key(packed);
    const RayEnd end = ray_to(grid, origin, key, max_range, ray);
    if (end == RayEnd::kOutside) return;
    if (point && end == RayEnd::kVoxel) out.hits.push_back(key);
    ray.cut = end == RayEnd::kCut;
    ray.origin = s;
    out.box.extend(ray.end_key);
    out.rays.push_back(ray);
  });
  return out;
}

// Thread t's share [begin, end) of n items split into `threads` contiguous chunks.
std::pair<std::size_t, std::size_t> share_of(std::size_t n, int threads, int t) {
  const std::size_t chunk = (n + std::size_t(threads) - 1) / std::size_t(threads);
  const std::size_t begin = std::min(n, std::size_t(t) * chunk);
  return {begin, std::min(n, begin + chunk)};
}

// The rays of a sweep: per scan and thread, its share's rays (see RayShare); the key box of all origins and
// ends.
struct SweepRays {
  std::vector<Origin> origins;
  std::vector<RayShare> shares;
  KeyBox box;

  [[nodiscard]] bool empty() const {
    return std::all_of(shares.begin(), shares.end(), [](const RayShare& s) { return s.rays.empty(); });
  }
};

// Scan `s`'s origin, as OctoMap sees it. @throws Error if it is not finite or outside the key range.
Origin scan_origin(const Scan& scan, std::size_t s, const octomap::OcTree& grid) {
  Origin origin{};
  for (int i = 0; i < 3; ++i) origin.p[i] = static_cast<float>(scan.origin_C[i]);
  if (!scan.origin_C.allFinite() ||
      !grid.coordToKeyChecked(origin.p[0], origin.p[1], origin.p[2], origin.key)) {
    throw Error("occupancy: scan " + std::to_string(s) + " of the sweep has its origin outside the map");
  }
  return origin;
}

// Adds scan `s`'s rays to `out`, its points and clear-only ray ends split into one share per thread, each
// thread converting, de-duplicating and making the rays of its own share.
void add_scan_rays(const Scan& scan, std::uint32_t s, const octomap::OcTree& grid, double max_range,
                   int threads, SweepRays& out) {
  const KeyConverter converter(grid);
  const Origin& origin = out.origins[s];
  const std::size_t first = out.shares.size();
  out.shares.resize(first + std::size_t(threads));
  parallel_for(threads, threads, [&](int t) {
    ShareKeys keys;
    const auto [begin, end] = share_of(scan.points_C.size(), threads, t);
    append_point_keys(scan.points_C.points, begin, end, converter, keys.points, keys.box);
    const auto [clear_begin, clear_end] = share_of(scan.clear_C.size(), threads, t);
    append_point_keys(scan.clear_C.points, clear_begin, clear_end, converter, keys.clear, keys.box);
    if (!keys.box.empty()) out.shares[first + std::size_t(t)] = share_rays(keys, grid, max_range, origin, s);
  });
  for (std::size_t i = first; i < out.shares.size(); ++i) {
    if (!out.shares[i].box.empty()) out.box.extend(out.shares[i].box);
  }
}

// The rays of every scan of `sweep`, with their origins.
SweepRays sweep_rays(const Sweep& sweep, const octomap::OcTree& grid, double max_range, int threads) {
  SweepRays out;
  for (std::size_t s = 0; s < sweep.scans.size(); ++s) {
    out.origins.push_back(scan_origin(sweep.scans[s], s, grid));
    out.box.extend(out.origins.back().key);
    add_scan_rays(sweep.scans[s], static_cast<std::uint32_t>(s), grid, max_range, threads, out);
  }
  return out;
}

// Blocks of rays dealt out in turn: neighbouring rays are of about the same length, far and near ones lie in
// different parts of an image, so contiguous halves can cost the threads very different times.
constexpr std::size_t kRaysPerBlock = 256;

// The rays of `rays` in blocks of at most kRaysPerBlock.
std::vector<std::pair<const Ray*, std::size_t>> ray_blocks(const SweepRays& rays) {
  std::vector<std::pair<const Ray*, std::size_t>> blocks;
  for (const RayShare& share : rays.shares) {
    for (std::size_t begin = 0; begin < share.rays.size(); begin += kRaysPerBlock)
      blocks.emplace_back(share.rays.data() + begin, std::min(kRaysPerBlock, share.rays.size() - begin));
  }
  return blocks;
}

// Walks thread `t`'s blocks of `blocks` (t, t + threads, …) into `cursor`.
template <class Cursor>
void walk_dealt(const SweepRays& rays, const std::vector<std::pair<const Ray*, std::size_t>>& blocks,
                std::size_t t, int threads, const octomap::OcTree& grid, const Cursor& cursor) {
  for (std::size_t b = t; b < blocks.size(); b += std::size_t(threads)) {
    for (const Ray* ray = blocks[b].first; ray != blocks[b].first + blocks[b].second; ++ray)
      walk(rays.origins[ray->origin], *ray, grid, cursor);
  }
}

// Walks the rays on `threads` threads, each into its own bit set over `bricks`, and returns their union
// (which does not depend on the split).
std::vector<std::uint64_t> walk_dense(const SweepRays& rays, const BrickGrid& bricks,
                                      const octomap::OcTree& grid, int threads) {
  std::vector<std::vector<std::uint64_t>> sets(static_cast<std::size_t>(threads));
  const auto blocks = ray_blocks(rays);
  parallel_for(threads, threads, [&](int thread) {
    const std::size_t t = std::size_t(thread);
    sets[t].assign(bricks.bits() / 64, 0);
    walk_dealt(rays, blocks, t, threads, grid, DenseCursor(bricks, sets[t].data()));
  });
  std::vector<std::uint64_t>& crossed = sets[0];
  for (std::size_t t = 1; t < sets.size(); ++t) {
    for (std::size_t w = 0; w < crossed.size(); ++w) crossed[w] |= sets[t][w];
  }
  return std::move(crossed);
}

// Walks the rays on `threads` threads, listing the packed keys they cross: sorted, each once.
std::vector<std::uint64_t> walk_sparse(const SweepRays& rays, const octomap::OcTree& grid, int threads) {
  std::vector<std::vector<std::uint64_t>> lists(static_cast<std::size_t>(threads));
  const auto blocks = ray_blocks(rays);
  parallel_for(threads, threads, [&](int t) {
    walk_dealt(rays, blocks, std::size_t(t), threads, grid, SparseCursor(lists[std::size_t(t)]));
  });
  std::vector<std::uint64_t> all;
  for (const auto& list : lists) all.insert(all.end(), list.begin(), list.end());
  return sorted_unique(std::move(all));
}

// Fills `update` from the dense bit sets: the hits' bits, the crossed voxels that are no hit, the non-empty
// bricks in the OcTree's depth-first order (sorted by index, not as 1 KB structs).
void dense_bricks(const BrickGrid& bricks, const std::vector<RayShare>& shares,
                  const std::vector<std::uint64_t>& crossed, KeyUpdate& update) {
  std::vector<std::uint64_t> occupied(bricks.bits() / 64, 0);
  for (const RayShare& share : shares) {
    for (const Key& k : share.hits) set_bit(occupied, bricks.index(k));
  }
  std::vector<std::pair<std::uint64_t, std::uint64_t>> order;  // (morton of the base, brick)
  for (std::uint64_t b = 0; b < bricks.bricks(); ++b) {
    std::uint64_t any = 0;
    for (std::size_t i = std::size_t(b) * kBrickWords; i < std::size_t(b + 1) * kBrickWords; ++i) {
      any |= occupied[i] | crossed[i];
    }
    if (any != 0) order.emplace_back(morton(bricks.brick_base(b)), b);
  }
  std::sort(order.begin(), order.end());
  update.bricks.resize(order.size());
  for (std::size_t n = 0; n < order.size(); ++n) {
    KeyBrick& brick = update.bricks[n];
    brick.base = bricks.brick_base(order[n].second);
    for (int w = 0; w < kBrickWords; ++w) {
      const std::size_t i = std::size_t(order[n].second) * kBrickWords + std::size_t(w);
      brick.occupied[std::size_t(w)] = occupied[i];
      brick.free[std::size_t(w)] = crossed[i] & ~occupied[i];
      update.occupied_count += std::size_t(__builtin_popcountll(brick.occupied[std::size_t(w)]));
      update.free_count += std::size_t(__builtin_popcountll(brick.free[std::size_t(w)]));
    }
  }
}

// Fills `update` from sorted key lists: the hits, the crossed keys (sorted, each once) that are no hit.
void sparse_bricks(const std::vector<RayShare>& shares, const std::vector<std::uint64_t>& crossed,
                   KeyUpdate& update) {
  std::vector<std::uint64_t> packed_hits;
  for (const RayShare& share : shares) {
    for (const Key& k : share.hits) packed_hits.push_back(pack_key(k));
  }
  const std::vector<std::uint64_t> occupied = sorted_unique(std::move(packed_hits));
  std::map<std::uint64_t, KeyBrick> bricks;  // by packed brick base
  auto mark = [&](std::uint64_t p, bool hit) {
    const Key k = unpack_key(p);
    KeyBrick& brick = bricks[pack_key(brick_base(k))];
    brick.base = brick_base(k);
    const int i = KeyBrick::local_index(k);
    (hit ? brick.occupied : brick.free)[std::size_t(i >> 6)] |= std::uint64_t{1} << (i & 63);
    ++(hit ? update.occupied_count : update.free_count);
  };
  for (const std::uint64_t p : occupied) mark(p, true);
  for (const std::uint64_t p : crossed) {
    if (!std::binary_search(occupied.begin(), occupied.end(), p)) mark(p, false);
  }
  for (auto& entry : bricks) update.bricks.push_back(entry.second);
  sort_depth_first(update.bricks);
}

}  // namespace

int KeyBrick::local_index(const octomap::OcTreeKey& key) {
  return kSpread4[key[0] & 0xf] | (kSpread4[key[1] & 0xf] << 1) | (kSpread4[key[2] & 0xf] << 2);
}

octomap::OcTreeKey KeyBrick::key(int index) const {
  int offset[3] = {0, 0, 0};
  for (int b = 0; b < 4; ++b) {
    for (int axis = 0; axis < 3; ++axis) offset[axis] |= ((index >> (3 * b + axis)) & 1) << b;
  }
  return Key(static_cast<std::uint16_t>(base[0] + offset[0]), static_cast<std::uint16_t>(base[1] + offset[1]),
             static_cast<std::uint16_t>(base[2] + offset[2]));
}

std::vector<octomap::OcTreeKey> KeyUpdate::occupied_keys() const {
  return keys_of(bricks, true);
}
std::vector<octomap::OcTreeKey> KeyUpdate::free_keys() const {
  return keys_of(bricks, false);
}

KeyUpdate compute_key_update(const Sweep& sweep, const octomap::OcTree& grid, double max_range, int threads) {
  if (!(max_range > 0.0)) throw Error("occupancy: max_range must be > 0, got " + std::to_string(max_range));
  threads = std::max(threads, 1);
  SweepRays rays = sweep_rays(sweep, grid, max_range, threads);
  KeyUpdate update;
  if (rays.empty()) return update;
  rays.box.grow();
  const BrickGrid bricks(rays.box);
  if (bricks.dense()) {
    dense_bricks(bricks, rays.shares, walk_dense(rays, bricks, grid, threads), update);
  } else {
    sparse_bricks(rays.shares, walk_sparse(rays, grid, threads), update);
  }
  return update;
}

void KeyUpdateUnion::add(const KeyUpdate& scan_update) {
  add(scan_update.bricks);
}

void KeyUpdateUnion::merge(KeyUpdateUnion& other) {
  if (bricks_.empty()) {
    std::swap(bricks_, other.bricks_);
    std::swap(index_, other.index_);
  } else {
    add(other.bricks_);
  }
  other.bricks_.clear();
  other.index_.clear();
}

void KeyUpdateUnion::add(const std::vector<KeyBrick>& bricks) {
  for (const KeyBrick& brick : bricks) {
    const auto [at, inserted] = index_.try_emplace(pack_key(brick.base), bricks_.size());
    if (inserted) {
      bricks_.push_back(brick);
      continue;
    }
    KeyBrick& gathered = bricks_[at->second];
    for (int w = 0; w < kBrickWords; ++w) {
      gathered.occupied[std::size_t(w)] |= brick.occupied[std::size_t(w)];
      gathered.free[std::size_t(w)] |= brick.free[std::size_t(w)];
    }
  }
}

KeyUpdate KeyUpdateUnion::take() {
  KeyUpdate update;
  // Sorted as (morton of the base, position) pairs rather than as 1 KB structs.
  std::vector<std::pair<std::uint64_t, std::size_t>> order;
  order.reserve(bricks_.size());
  for (std::size_t b = 0; b < bricks_.size(); ++b) order.emplace_back(morton(bricks_[b].base), b);
  std::sort(order.begin(), order.end());
  update.bricks.reserve(order.size());
  for (const auto& entry : order) {
    KeyBrick& brick = update.bricks.emplace_back(bricks_[entry.second]);
    for (int w = 0; w < kBrickWords; ++w) {
      // A voxel one scan cleared and another hit is a hit of the sweep.
      brick.free[std::size_t(w)] &= ~brick.occupied[std::size_t(w)];
      update.occupied_count += std::size_t(__builtin_popcountll(brick.occupied[std::size_t(w)]));
      update.free_count += std::size_t(__builtin_popcountll(brick.free[std::size_t(w)]));
    }
  }
  bricks_.clear();
  index_.clear();
  return update;
}

}  // namespace cellmap
