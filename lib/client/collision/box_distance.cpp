#include "cellmap/collision/box_distance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace cellmap::collision {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// B expressed in A's frame: R = R_AB (columns are B's axes in A), t = p_AB (B's centre in A).
struct Relative {
  Matrix3d R;
  Vector3d t;
};

Relative relative(const Obb& a, const Obb& b) {
  return {a.rotation.transpose() * b.rotation, a.rotation.transpose() * (b.center - a.center)};
}

// ---------------------------------------------------------------------------------------------------------
// GJK on the Minkowski difference D = A - B, computed in A's frame.

// A vertex of D with the box vertices it comes from; `id` packs the sign patterns of both (6 bits), so a
// repeated support vertex is recognised exactly.
struct Vertex {
  Vector3d w;
  int id = -1;
};

// A's vertex of a support vertex, from the sign bits; B's vertex is then a - w.
Vector3d vertex_a(int id, const Vector3d& ha) {
  return Vector3d((id & 1) ? ha[0] : -ha[0], (id & 2) ? ha[1] : -ha[1], (id & 4) ? ha[2] : -ha[2]);
}

struct Support {
  const Vector3d& ha;
  const Vector3d& hb;
  const Relative& rel;

  Vertex operator()(const Vector3d& d) const {
    Vertex v;
    int id = 0;
    Vector3d a;
    for (int k = 0; k < 3; ++k) {
      const bool positive = d[k] >= 0.0;
      a[k] = positive ? ha[k] : -ha[k];
      id |= positive ? (1 << k) : 0;
    }
    const Vector3d d_b = -(rel.R.transpose() * d);
    Vector3d s_b;
    for (int k = 0; k < 3; ++k) {
      const bool positive = d_b[k] >= 0.0;
      s_b[k] = positive ? hb[k] : -hb[k];
      id |= positive ? (8 << k) : 0;
    }
    v.w = a - (rel.R * s_b + rel.t);
    v.id = id;
    return v;
  }
};

// The simplex and the barycentric weights of its closest point to the origin.
struct Simplex {
  std::array<Vertex, 4> v;
  std::array<double, 4> lambda{};
  int n = 0;
};

// Closest point to the origin of a sub-simplex given by vertex indices; the "signed volumes" sub-algorithm
// (Montanari, Petrinic, Barbieri, ACM TOG 2017): decide the supporting face by signs of (projected) volumes,
// which stays robust for nearly degenerate simplices, and recurse on the faces only when needed.
struct SubResult {
  std::array<int, 4> index{};
  std::array<double, 4> lambda{};
  int n = 0;
  double distance2 = std::numeric_limits<double>::infinity();
};

SubResult closest_vertex(const std::array<Vertex, 4>& s, int i) {
  SubResult r;
  r.index[0] = i;
  r.lambda[0] = 1.0;
  r.n = 1;
  r.distance2 = s[i].w.squaredNorm();
  return r;
}

SubResult closest_segment(const std::array<Vertex, 4>& s, int i0, int i1) {
  const Vector3d& p0 = s[i0].w;
  const Vector3d& p1 = s[i1].w;
  const Vector3d u = p1 - p0;
  const double uu = u.squaredNorm();
  if (!(uu > 0.0)) return closest_vertex(s, p0.squaredNorm() <= p1.squaredNorm() ? i0 : i1);
  const double along = -p0.dot(u);
  if (along <= 0.0) return closest_vertex(s, i0);
  if (along >= uu) return closest_vertex(s, i1);
  SubResult r;
  r.n = 2;
  r.index[0] = i0;
  r.index[1] = i1;
  r.lambda[1] = along / uu;
  r.lambda[0] = 1.0 - r.lambda[1];
  r.distance2 = (p0 + r.lambda[1] * u).squaredNorm();
  return r;
}

// Edge of a triangle, vertex indices in increasing order (the GJK loop compacts the simplex in place).
SubResult closest_edge(const std::array<Vertex, 4>& s, int i, int j) {
  return i < j ? closest_segment(s, i, j) : closest_segment(s, j, i);
}

double cross2(double ax, double ay, double bx, double by) {
  return ax * by - ay * bx;
}

SubResult closest_triangle(const std::array<Vertex, 4>& s, int i0, int i1, int i2) {
  const std::array<int, 3> idx{i0, i1, i2};
  const Vector3d& p0 = s[i0].w;
  const Vector3d& p1 = s[i1].w;
  const Vector3d& p2 = s[i2].w;
  const Vector3d n = (p1 - p0).cross(p2 - p0);
  const double nn = n.squaredNorm();
  const double scale = (p1 - p0).squaredNorm() * (p2 - p0).squaredNorm();
  SubResult best;
  if (nn > 1e-28 * scale && nn > 0.0) {
    // Project the origin onto the plane, then measure signed areas in the coordinate plane where the
    // triangle's projection is largest (the component of n with the largest magnitude).
    const Vector3d po = n * (n.dot(p0) / nn);
    int k = 0;
    n.cwiseAbs().maxCoeff(&k);
    const int x = (k + 1) % 3;
    const int y = (k + 2) % 3;
    const double mu = n[k];
    const std::array<const Vector3d*, 3> p{&p0, &p1, &p2};
    std::array<double, 3> c{};
    bool inside = true;
    for (int j = 0; j < 3; ++j) {
      const Vector3d& q1 = *p[(j + 1) % 3];
      const Vector3d& q2 = *p[(j + 2) % 3];
      c[j] = cross2(q1[x] - po[x], q1[y] - po[y], q2[x] - po[x], q2[y] - po[y]);
      inside = inside && (c[j] * mu > 0.0);
    }
    if (inside) {
      best.n = 3;
      for (int j = 0; j < 3; ++j) {
        best.index[j] = idx[j];
        best.lambda[j] = c[j] / mu;
      }
      best.distance2 = po.squaredNorm();
      return best;
    }
    for (int j = 0; j < 3; ++j) {
      if (c[j] * mu > 0.0) continue;  // the origin's projection is on the inner side of the edge opposite j
      const SubResult edge = closest_edge(s, idx[(j + 1) % 3], idx[(j + 2) % 3]);
      if (edge.distance2 < best.distance2) best = edge;
    }
    return best;
  }
  // Degenerate (collinear) triangle: the closest point lies on one of its edges.
  for (int j = 0; j < 3; ++j) {
    const SubResult edge = closest_edge(s, idx[(j + 1) % 3], idx[(j + 2) % 3]);
    if (edge.distance2 < best.distance2) best = edge;
  }
  return best;
}

double volume(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a));
}

// Returns n = 4 (origin inside) or the closest face/edge/vertex.
SubResult closest_tetrahedron(const std::array<Vertex, 4>& s) {
  const Vector3d& p0 = s[0].w;
  const Vector3d& p1 = s[1].w;
  const Vector3d& p2 = s[2].w;
  const Vector3d& p3 = s[3].w;
  const Vector3d zero = Vector3d::Zero();
  const double total = volume(p0, p1, p2, p3);
  const double scale2 = (p1 - p0).squaredNorm() * (p2 - p0).squaredNorm() * (p3 - p0).squaredNorm();
  const std::array<double, 4> c{volume(zero, p1, p2, p3), volume(p0, zero, p2, p3), volume(p0, p1, zero, p3),
                                volume(p0, p1, p2, zero)};
  const bool degenerate = !(total * total > 1e-28 * scale2);
  SubResult best;
  if (!degenerate && c[0] * total > 0.0 && c[1] * total > 0.0 && c[2] * total > 0.0 && c[3] * total > 0.0) {
    best.n = 4;
    for (int j = 0; j < 4; ++j) {
      best.index[j] = j;
      best.lambda[j] = c[j] / total;
    }
    best.distance2 = 0.0;
    return best;
  }
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (int j = 0; j < 4; ++j) {
    if (!degenerate && c[j] * total > 0.0) continue;
    const SubResult face = closest_triangle(s, kFace[j][0], kFace[j][1], kFace[j][2]);
    if (face.distance2 < best.distance2) best = face;
  }
  return best;
}

// Runs GJK in A's frame; returns points in A's frame. `simplex_out` receives the final simplex (for EPA).
GjkResult gjk_relative(const Vector3d& ha, const Vector3d& hb, const Relative& rel,
                       Simplex* simplex_out = nullptr, const Vector3d* towards_b = nullptr) {
  const Support support{ha, hb, rel};
  // (|ha| + |hb| + |t|)^2 <= 3 (|ha|^2 + |hb|^2 + |t|^2): a scene size without square roots.
  const double scale2 = 3.0 * (ha.squaredNorm() + hb.squaredNorm() + rel.t.squaredNorm());
  const double tiny2 = std::max(1e-24 * scale2, std::numeric_limits<double>::min());
  constexpr double kRelative = 1e-14;
  constexpr int kMaxIterations = 64;

  Simplex simplex;
  // Start from D's centre (-t), or from a known direction A → B (a separating axis): the first support point
  // is then in the direction of the origin.
  Vector3d v = towards_b != nullptr ? Vector3d(-*towards_b) : Vector3d(-rel.t);
  if (!(v.squaredNorm() > tiny2)) v = Vector3d(1.0, 0.0, 0.0) * std::max(std::sqrt(scale2), 1.0);
  double vv = std::numeric_limits<double>::infinity();
  GjkResult result;
  bool intersecting = false;
  int iteration = 0;
  for (; iteration < kMaxIterations; ++iteration) {
    const Vertex w = support(-v);
    bool repeated = false;
    for (int i = 0; i < simplex.n; ++i) repeated = repeated || simplex.v[i].id == w.id;
    if (repeated) break;
    if (simplex.n > 0 && vv - v.dot(w.w) <= kRelative * vv) break;

    // Tentatively append w (slot n); the simplex is only changed for good when the distance decreases.
    const int n = simplex.n;
    simplex.v[n] = w;
    SubResult sub;
    switch (n + 1) {
      case 1:
        sub = closest_vertex(simplex.v, 0);
        break;
      case 2:
        sub = closest_segment(simplex.v, 0, 1);
        break;
      case 3:
        sub = closest_triangle(simplex.v, 0, 1, 2);
        break;
      default:
        sub = closest_tetrahedron(simplex.v);
        break;
    }
    if (sub.n == 4) {
      simplex.n = 4;
      for (int i = 0; i < 4; ++i) simplex.lambda[i] = sub.lambda[i];
      intersecting = true;
      v = Vector3d::Zero();
      break;
    }
    Vector3d v_next = sub.lambda[0] * simplex.v[sub.index[0]].w;
    for (int i = 1; i < sub.n; ++i) v_next += sub.lambda[i] * simplex.v[sub.index[i]].w;
    const double vv_next = v_next.squaredNorm();
    if (n > 0 && !(vv_next < vv)) break;  // no progress: rounding floor reached, keep the last simplex
    // Indices come in increasing order, so compacting in place is safe.
    for (int i = 0; i < sub.n; ++i) {
      if (sub.index[i] != i) simplex.v[i] = simplex.v[sub.index[i]];
      simplex.lambda[i] = sub.lambda[i];
    }
    simplex.n = sub.n;
    v = v_next;
    vv = vv_next;
    if (vv <= tiny2) {
      intersecting = true;
      break;
    }
  }
  result.iterations = iteration;
  result.intersecting = intersecting;
  Vector3d pa = Vector3d::Zero();
  Vector3d pb = Vector3d::Zero();
  for (int i = 0; i < simplex.n; ++i) {
    const Vector3d a = vertex_a(simplex.v[i].id, ha);
    pa += simplex.lambda[i] * a;
    pb += simplex.lambda[i] * (a - simplex.v[i].w);
  }
  result.point_a = pa;
  result.point_b = pb;
  result.distance = intersecting ? 0.0 : std::sqrt(std::max(vv, 0.0));
  if (simplex_out != nullptr) *simplex_out = simplex;
  return result;
}

// The largest separation along the 15 axes (negative: minus the smallest overlap), exact rotation terms, with
// the unit axis in A's frame pointing from A to B and which axis it is.
struct SatResult {
  double gap = -std::numeric_limits<double>::infinity();
  Vector3d axis = Vector3d::UnitX();
  enum Kind { kFaceA, kFaceB, kEdges } kind = kFaceA;
  int i = 0;  // face of A, or A's edge direction
  int j = 0;  // face of B, or B's edge direction
};

// With faces_only, just the 6 face axes: a valid lower bound when positive, and cheap.
// Inlined into its callers so that R and t stay in registers (a measurable share of a box-box query).
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline SatResult
sat_relative(const Vector3d& ha, const Vector3d& hb, const Relative& rel, bool faces_only = false) {
  const Matrix3d& R = rel.R;
  const Vector3d& t = rel.t;
  const Matrix3d absR = R.cwiseAbs();
  double gap[15];
  double tb[3];
  for (int i = 0; i < 3; ++i) gap[i] = std::abs(t[i]) - ha[i] - hb.dot(absR.row(i));
  for (int j = 0; j < 3; ++j) {
    tb[j] = t.dot(R.col(j));
    gap[3 + j] = std::abs(tb[j]) - ha.dot(absR.col(j)) - hb[j];
  }
  int k = 0;
  for (int m = 1; m < 6; ++m) k = gap[m] > gap[k] ? m : k;
  const auto face_result = [&](int face) {
    SatResult best;
    best.gap = gap[face];
    if (face < 3) {
      best.kind = SatResult::kFaceA;
      best.i = face;
      best.axis = Vector3d::Unit(face) * (t[face] >= 0.0 ? 1.0 : -1.0);
    } else {
      best.kind = SatResult::kFaceB;
      best.j = face - 3;
      best.axis = R.col(face - 3) * (tb[face - 3] >= 0.0 ? 1.0 : -1.0);
    }
    return best;
  };
  if (faces_only) return face_result(k);
  // Edge axes: L = e_i x R.col(j), |L|^2 = R(i1, j)^2 + R(i2, j)^2. Near-parallel edges (|L| < 1e-8) are
  // skipped: their facets of the Minkowski difference degenerate and the neighbouring axes bound the same
  // overlap.
  double tl[9];
  double numerator[9];
  double length2[9];
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3;
    const int i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3;
      const int j2 = (j + 2) % 3;
      const int m = 3 * i + j;
      length2[m] = R(i1, j) * R(i1, j) + R(i2, j) * R(i2, j);
      const double ra = ha[i1] * absR(i2, j) + ha[i2] * absR(i1, j);
      const double rb = hb[j1] * absR(i, j2) + hb[j2] * absR(i, j1);
      tl[m] = t[i2] * R(i1, j) - t[i1] * R(i2, j);
      numerator[m] = std::abs(tl[m]) - ra - rb;
    }
  }
  for (int m = 0; m < 9; ++m) {
    gap[6 + m] = -std::numeric_limits<double>::infinity();
    if (length2[m] < 1e-16) continue;
    // With a positive gap known, an edge axis can only win with a positive numerator and then the comparison
    // needs no square root; most edge axes are discarded here.
    const double best = gap[k];
    if (best > 0.0 && (numerator[m] <= 0.0 || numerator[m] * numerator[m] <= best * best * length2[m]))
      continue;
    gap[6 + m] = numerator[m] / std::sqrt(length2[m]);
    if (gap[6 + m] > best) k = 6 + m;
  }
  if (k < 6) return face_result(k);
  SatResult best;
  best.gap = gap[k];
  best.kind = SatResult::kEdges;
  best.i = (k - 6) / 3;
  best.j = (k - 6) % 3;
  const Vector3d L = Vector3d::Unit(best.i).cross(R.col(best.j));
  best.axis = L * ((tl[k - 6] >= 0.0 ? 1.0 : -1.0) / L.norm());
  return best;
}

double sign_of(double x) {
  return x >= 0.0 ? 1.0 : -1.0;
}

// Exact distance certificate: the separating axis gives a lower bound `gap` on the distance; if the support
// features along it hold a pair of points exactly `gap` apart (a vertex projecting into the facing face, or
// two edges whose common perpendicular meets both), that pair is a closest pair. Returns false otherwise.
bool certify_axis(const Vector3d& ha, const Vector3d& hb, const Relative& rel, const SatResult& sat,
                  Vector3d* pa, Vector3d* pb) {
  const Matrix3d& R = rel.R;
  const Vector3d& t = rel.t;
  if (sat.kind == SatResult::kFaceA) {
    // B's vertex deepest towards A's face i.
    const int i = sat.i;
    const double s = sat.axis[i];
    const Vector3d sigma(sign_of(-s * R(i, 0)), sign_of(-s * R(i, 1)), sign_of(-s * R(i, 2)));
    const Vector3d v = t + R * sigma.cwiseProduct(hb);
    const int k1 = (i + 1) % 3, k2 = (i + 2) % 3;
    if (std::abs(v[k1]) > ha[k1] || std::abs(v[k2]) > ha[k2]) return false;
    *pb = v;
    *pa = v;
    (*pa)[i] = s * ha[i];
    return true;
  }
  if (sat.kind == SatResult::kFaceB) {
    // A's vertex deepest towards B's face j, tested in B's frame.
    const int j = sat.j;
    const double s = sign_of(sat.axis.dot(R.col(j)));
    const Vector3d u =
        Vector3d(sign_of(s * R(0, j)), sign_of(s * R(1, j)), sign_of(s * R(2, j))).cwiseProduct(ha);
    Vector3d u_B = R.transpose() * (u - t);
    const int k1 = (j + 1) % 3, k2 = (j + 2) % 3;
    if (std::abs(u_B[k1]) > hb[k1] || std::abs(u_B[k2]) > hb[k2]) return false;
    *pa = u;
    u_B[j] = -s * hb[j];
    *pb = t + R * u_B;
    return true;
  }
  // Edge-edge: A's edge along e_i and B's edge along R.col(j), the ones extreme along the axis.
  const int i = sat.i;
  const int j = sat.j;
  const Vector3d& L = sat.axis;
  Vector3d a0(sign_of(L[0]) * ha[0], sign_of(L[1]) * ha[1], sign_of(L[2]) * ha[2]);
  a0[i] = 0.0;
  const Vector3d L_B = R.transpose() * L;
  Vector3d b_local(sign_of(-L_B[0]) * hb[0], sign_of(-L_B[1]) * hb[1], sign_of(-L_B[2]) * hb[2]);
  b_local[j] = 0.0;
  const Vector3d b0 = t + R * b_local;
  const Vector3d d2 = R.col(j);
  const Vector3d r = a0 - b0;
  const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
  const double a12 = R(i, j);
  const double c1 = r[i];
  const double c2 = d2.dot(r);
  const double alpha = (a12 * c2 - c1) / (R(i1, j) * R(i1, j) + R(i2, j) * R(i2, j));  // = 1 - a12^2 > 1e-16
  const double beta = c2 + alpha * a12;
  if (std::abs(alpha) > ha[i] || std::abs(beta) > hb[j]) return false;
  *pa = a0;
  (*pa)[i] += alpha;
  *pb = b0 + beta * d2;
  return true;
}

// Second certificate: start at a vertex extreme along the axis and alternate closest-point projections
// between the boxes (a few steps); when a point maps back onto itself the two points are mutually closest,
// and mutually closest points of two convex sets are a closest pair (the direction between them lies in both
// normal cones). Covers vertex-vertex, vertex-edge and many edge-face contacts.
bool certify_vertex(const Vector3d& ha, const Vector3d& hb, const Relative& rel, const SatResult& sat,
                    Vector3d* pa, Vector3d* pb) {
  const Matrix3d& R = rel.R;
  const Vector3d& t = rel.t;
  const double tolerance2 = 1e-26 * (ha.squaredNorm() + hb.squaredNorm() + t.squaredNorm());
  constexpr int kSteps = 3;
  // From B's vertex extreme towards A: p = closest point of A, q = closest point of B to p, and so on.
  const Vector3d L_B = R.transpose() * sat.axis;
  Vector3d q_B(sign_of(-L_B[0]) * hb[0], sign_of(-L_B[1]) * hb[1], sign_of(-L_B[2]) * hb[2]);
  for (int step = 0; step < kSteps; ++step) {
    const Vector3d q = t + R * q_B;
    const Vector3d p = q.cwiseMax(-ha).cwiseMin(ha);
    const Vector3d next_B = (R.transpose() * (p - t)).cwiseMax(-hb).cwiseMin(hb);
    if ((next_B - q_B).squaredNorm() <= tolerance2) {
      *pa = p;
      *pb = q;
      return true;
    }
    q_B = next_B;
  }
  // From A's vertex extreme towards B, symmetric.
  Vector3d p(sign_of(sat.axis[0]) * ha[0], sign_of(sat.axis[1]) * ha[1], sign_of(sat.axis[2]) * ha[2]);
  for (int step = 0; step < kSteps; ++step) {
    const Vector3d q = t + R * (R.transpose() * (p - t)).cwiseMax(-hb).cwiseMin(hb);
    const Vector3d next = q.cwiseMax(-ha).cwiseMin(ha);
    if ((next - p).squaredNorm() <= tolerance2) {
      *pa = p;
      *pb = q;
      return true;
    }
    p = next;
  }
  return false;
}

bool certify(const Vector3d& ha, const Vector3d& hb, const Relative& rel, const SatResult& sat, Vector3d* pa,
             Vector3d* pb) {
  return certify_axis(ha, hb, rel, sat, pa, pb) || certify_vertex(ha, hb, rel, sat, pa, pb);
}

// Distance of separated boxes (sat.gap > 0) in A's frame: the certificate when it applies, else GJK started
// along the separating axis.
GjkResult separated_relative(const Vector3d& ha, const Vector3d& hb, const Relative& rel,
                             const SatResult& sat) {
  GjkResult result;
  if (certify(ha, hb, rel, sat, &result.point_a, &result.point_b)) {
    result.distance = (result.point_b - result.point_a).norm();
    return result;
  }
  return gjk_relative(ha, hb, rel, nullptr, &sat.axis);
}

}  // namespace

bool overlap(const Obb& a, const Obb& b, double margin) {
  const Matrix3d R = a.rotation.transpose() * b.rotation;
  const Vector3d t = a.rotation.transpose() * (b.center - a.center);
  // The epsilon keeps near-parallel edge axes (cross products ~ 0) from separating by rounding alone
  // (Gottschalk, Lin, Manocha 1996); it makes the test conservative by ~1e-6 of the box size on edge axes.
  const Matrix3d absR = R.cwiseAbs().array() + 1e-6;
  const Vector3d& ha = a.half_extents;
  const Vector3d& hb = b.half_extents;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(t[i]) > ha[i] + hb.dot(absR.row(i)) + margin) return false;
  }
  for (int j = 0; j < 3; ++j) {
    if (std::abs(t.dot(R.col(j))) > ha.dot(absR.col(j)) + hb[j] + margin) return false;
  }
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3;
    const int i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3;
      const int j2 = (j + 2) % 3;
      const double ra = ha[i1] * absR(i2, j) + ha[i2] * absR(i1, j);
      const double rb = hb[j1] * absR(i, j2) + hb[j2] * absR(i, j1);
      const double tl = t[i2] * R(i1, j) - t[i1] * R(i2, j);
      // |L| = sin(angle between the edges); only needed when there is a margin.
      const double grow = margin > 0.0 ? margin * std::sqrt(std::max(0.0, 1.0 - R(i, j) * R(i, j))) : 0.0;
      if (std::abs(tl) > ra + rb + grow) return false;
    }
  }
  return true;
}

SignedDistance separating_axis_depth(const Obb& a, const Obb& b) {
  const SatResult sat = sat_relative(a.half_extents, b.half_extents, relative(a, b));
  SignedDistance out;
  out.distance = sat.gap;
  out.normal = a.rotation * sat.axis;
  return out;
}

GjkResult gjk_distance(const Obb& a, const Obb& b) {
  const Relative rel = relative(a, b);
  GjkResult result = gjk_relative(a.half_extents, b.half_extents, rel);
  result.point_a = a.rotation * result.point_a + a.center;
  result.point_b = a.rotation * result.point_b + a.center;
  return result;
}

namespace {

// Penetration witness points: B moved out along the normal by depth + clearance touches nothing, and GJK's
// closest points there (exactly `clearance` apart, along the normal) map back to A and the original B.
SignedDistance penetration_witnesses(const Obb& a, const Obb& b, const Relative& rel, double depth,
                                     const Vector3d& axis_a) {
  const double clearance = std::max(a.half_extents.norm() + b.half_extents.norm(), 1e-3);
  const double shift = depth + clearance;
  Relative moved = rel;
  moved.t += shift * axis_a;
  SatResult sat = sat_relative(a.half_extents, b.half_extents, moved);
  if (!(sat.gap > 0.0)) sat = {clearance, axis_a, SatResult::kFaceA, 0, 0};  // rounding; GJK decides below
  const GjkResult g = separated_relative(a.half_extents, b.half_extents, moved, sat);
  Vector3d pa = g.point_a;
  Vector3d pb = g.point_b - shift * axis_a;
  if (g.intersecting) {  // cannot happen for a true separating direction; stay finite regardless
    pa = Vector3d::Zero();
    pb = -depth * axis_a;
  }
  SignedDistance out;
  out.distance = -depth;
  out.point_a = a.rotation * pa + a.center;
  out.point_b = a.rotation * pb + a.center;
  out.normal = a.rotation * axis_a;
  return out;
}

}  // namespace

SignedDistance signed_distance(const Obb& a, const Obb& b) {
  const Relative rel = relative(a, b);
  const auto separated = [&](const GjkResult& g, const Vector3d& axis) {
    SignedDistance out;
    out.distance = g.distance;
    out.point_a = a.rotation * g.point_a + a.center;
    out.point_b = a.rotation * g.point_b + a.center;
    // A positive separation exceeds the rounding floor, so the direction is well defined; a certified pair
    // at zero distance cannot occur (the axis gap is positive), the fallback only guards against rounding.
    const Vector3d gap = g.point_b - g.point_a;
    out.normal = a.rotation * (gap.squaredNorm() > 0.0 ? Vector3d(gap.normalized()) : axis);
    return out;
  };
  // Fast path: a face axis already separates and a certificate holds (most separated pairs).
  const SatResult faces = sat_relative(a.half_extents, b.half_extents, rel, true);
  if (faces.gap > 0.0) {
    GjkResult g;
    if (certify(a.half_extents, b.half_extents, rel, faces, &g.point_a, &g.point_b)) {
      g.distance = (g.point_b - g.point_a).norm();
      return separated(g, faces.axis);
    }
  }
  const SatResult sat = sat_relative(a.half_extents, b.half_extents, rel);
  if (sat.gap > 0.0) {
    const GjkResult g = separated_relative(a.half_extents, b.half_extents, rel, sat);
    if (!g.intersecting) return separated(g, sat.axis);
  }
  // Touching (within rounding) or overlapping: the separating axes give the exact depth and its normal.
  return penetration_witnesses(a, b, rel, std::max(-sat.gap, 0.0), sat.axis);
}

namespace {

// EPA on the Minkowski difference, in A's frame, starting from GJK's enclosing tetrahedron.
struct Face {
  std::array<int, 3> v;
  Vector3d normal;  // unit, outward
  double distance;  // of the face's plane from the origin (>= 0 while the origin is inside)
  bool alive = true;
};

bool make_face(const std::vector<Vertex>& vertices, int i0, int i1, int i2, Face* face) {
  const Vector3d n = (vertices[i1].w - vertices[i0].w).cross(vertices[i2].w - vertices[i0].w);
  const double length = n.norm();
  if (!(length > 0.0)) return false;
  face->v = {i0, i1, i2};
  face->normal = n / length;
  face->distance = face->normal.dot(vertices[i0].w);
  face->alive = true;
  return true;
}

}  // namespace

SignedDistance epa_penetration(const Obb& a, const Obb& b) {
  const Relative rel = relative(a, b);
  Simplex simplex;
  const GjkResult g = gjk_relative(a.half_extents, b.half_extents, rel, &simplex);
  const SatResult sat = sat_relative(a.half_extents, b.half_extents, rel);
  const double sat_gap = sat.gap;
  const Vector3d& sat_axis = sat.axis;
  if (!g.intersecting) {
    SignedDistance out;
    out.distance = g.distance;
    out.point_a = a.rotation * g.point_a + a.center;
    out.point_b = a.rotation * g.point_b + a.center;
    out.normal = a.rotation * (g.point_b - g.point_a).normalized();
    return out;
  }
  const Support support{a.half_extents, b.half_extents, rel};
  const double scale = a.half_extents.norm() + b.half_extents.norm() + rel.t.norm();
  // GJK may stop on a segment or triangle through the origin (inside D): grow it to a tetrahedron by support
  // points in directions that leave its span. If D itself is flat the depth is 0.
  const double flat = 1e-12 * scale;
  for (int attempt = 0; simplex.n < 4 && attempt < 3; ++attempt) {
    std::vector<Vector3d> directions;
    if (simplex.n == 1) {
      for (int k = 0; k < 3; ++k)
        directions.insert(directions.end(), {Vector3d::Unit(k), -Vector3d::Unit(k)});
    } else if (simplex.n == 2) {
      const Vector3d d = (simplex.v[1].w - simplex.v[0].w).normalized();
      int k = 0;
      d.cwiseAbs().minCoeff(&k);
      const Vector3d e1 = d.cross(Vector3d::Unit(k)).normalized();
      const Vector3d e2 = d.cross(e1);
      directions = {e1, -e1, e2, -e2};
    } else {
      const Vector3d n =
          (simplex.v[1].w - simplex.v[0].w).cross(simplex.v[2].w - simplex.v[0].w).normalized();
      const double side = n.dot(simplex.v[0].w) > 0.0 ? -1.0 : 1.0;  // towards the origin first
      directions = {side * n, -side * n};
    }
    bool grown = false;
    for (const Vector3d& direction : directions) {
      const Vertex w = support(direction);
      double off = 0.0;  // distance of w from the current simplex's affine span
      if (simplex.n == 1) {
        off = (w.w - simplex.v[0].w).norm();
      } else if (simplex.n == 2) {
        const Vector3d d = (simplex.v[1].w - simplex.v[0].w).normalized();
        const Vector3d r = w.w - simplex.v[0].w;
        off = (r - r.dot(d) * d).norm();
      } else {
        const Vector3d n =
            (simplex.v[1].w - simplex.v[0].w).cross(simplex.v[2].w - simplex.v[0].w).normalized();
        off = std::abs(n.dot(w.w - simplex.v[0].w));
      }
      if (off > flat) {
        simplex.v[simplex.n++] = w;
        grown = true;
        break;
      }
    }
    if (!grown) break;
  }
  if (simplex.n < 4) return penetration_witnesses(a, b, rel, std::max(-sat_gap, 0.0), sat_axis);
  std::vector<Vertex> vertices(simplex.v.begin(), simplex.v.end());
  std::vector<Face> faces;
  const Vector3d centroid = 0.25 * (vertices[0].w + vertices[1].w + vertices[2].w + vertices[3].w);
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (const auto& f : kFace) {
    Face face;
    if (!make_face(vertices, f[0], f[1], f[2], &face)) continue;
    if (face.normal.dot(vertices[f[0]].w - centroid) < 0.0) make_face(vertices, f[0], f[2], f[1], &face);
    faces.push_back(face);
  }
  const Face* closest = nullptr;
  for (int iteration = 0; iteration < 128 && !faces.empty(); ++iteration) {
    closest = nullptr;
    for (const Face& face : faces) {
      if (face.alive && (closest == nullptr || face.distance < closest->distance)) closest = &face;
    }
    if (closest == nullptr) break;
    const Vertex w = support(closest->normal);
    bool known = false;
    for (const Vertex& v : vertices) known = known || v.id == w.id;
    if (known || closest->normal.dot(w.w) - closest->distance <= 1e-13 * scale) break;
    // Remove the faces w sees and stitch the horizon to w.
    const int wi = static_cast<int>(vertices.size());
    vertices.push_back(w);
    std::vector<std::array<int, 2>> horizon;
    for (Face& face : faces) {
      if (!face.alive || face.normal.dot(w.w - vertices[face.v[0]].w) <= 0.0) continue;
      face.alive = false;
      for (int e = 0; e < 3; ++e) {
        const std::array<int, 2> edge{face.v[e], face.v[(e + 1) % 3]};
        const auto twin = std::find(horizon.begin(), horizon.end(), std::array<int, 2>{edge[1], edge[0]});
        if (twin != horizon.end()) {
          horizon.erase(twin);
        } else {
          horizon.push_back(edge);
        }
      }
    }
    std::vector<Face> kept;
    for (const Face& face : faces) {
      if (face.alive) kept.push_back(face);
    }
    for (const auto& edge : horizon) {
      Face face;
      if (make_face(vertices, edge[0], edge[1], wi, &face)) kept.push_back(face);
    }
    faces.swap(kept);
    closest = nullptr;
  }
  if (closest == nullptr) {
    for (const Face& face : faces) {
      if (face.alive && (closest == nullptr || face.distance < closest->distance)) closest = &face;
    }
  }
  if (closest == nullptr) return penetration_witnesses(a, b, rel, std::max(-sat_gap, 0.0), sat_axis);
  // Barycentric coordinates of the origin's projection on the closest face give the witness points.
  const Vector3d p = closest->distance * closest->normal;
  const Vector3d& v0 = vertices[closest->v[0]].w;
  const Vector3d& v1 = vertices[closest->v[1]].w;
  const Vector3d& v2 = vertices[closest->v[2]].w;
  const Vector3d& n = closest->normal;
  const double area = n.dot((v1 - v0).cross(v2 - v0));
  const double l0 = n.dot((v1 - p).cross(v2 - p)) / area;
  const double l1 = n.dot((v2 - p).cross(v0 - p)) / area;
  const double l2 = 1.0 - l0 - l1;
  const std::array<double, 3> lambda{l0, l1, l2};
  Vector3d pa = Vector3d::Zero();
  Vector3d pb = Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    const Vertex& v = vertices[closest->v[i]];
    const Vector3d va = vertex_a(v.id, a.half_extents);
    pa += lambda[i] * va;
    pb += lambda[i] * (va - v.w);
  }
  SignedDistance out;
  out.distance = -std::max(closest->distance, 0.0);
  out.point_a = a.rotation * pa + a.center;
  out.point_b = a.rotation * pb + a.center;
  out.normal = a.rotation * n;
  return out;
}

}  // namespace cellmap::collision
