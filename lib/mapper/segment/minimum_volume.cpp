// SPDX-License-Identifier: Apache-2.0
#include "minimum_volume.hpp"

#include <libqhull_r/qhull_ra.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>

namespace cellmap::detail {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr std::size_t kPolished = 12;  // flush boxes polished by the local search, best first

double cross(const Vector2d& o, const Vector2d& a, const Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Andrew's monotone chain: the convex hull counter-clockwise, without collinear points.
std::vector<Vector2d> hull_2d(std::vector<Vector2d> p) {
  std::sort(p.begin(), p.end(), [](const Vector2d& a, const Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (p.size() < 3) return p;
  std::vector<Vector2d> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

struct Rectangle {
  Vector2d direction = Vector2d::UnitX();  // of its first side
  double width = 0, height = 0;
};

// Minimum-area enclosing rectangle of a convex polygon (counter-clockwise): one side lies on a polygon edge
// (Freeman and Shapira 1975), found for every edge by rotating calipers in O(h). `padding` is added to both
// sides before comparing areas, so that flat polygons still compare sensibly.
Rectangle min_area_rectangle(const std::vector<Vector2d>& hull, double padding) {
  const std::size_t h = hull.size();
  Rectangle best;
  if (h < 3) {
    if (h == 2 && hull[1] != hull[0]) best.direction = (hull[1] - hull[0]).normalized();
    if (h == 2) best.width = (hull[1] - hull[0]).norm();
    return best;
  }
  double best_area = std::numeric_limits<double>::infinity();
  std::size_t right = 1, top = 1, left = 1;
  const auto advance = [&](std::size_t& index, const Vector2d& axis, double sense) {
    for (std::size_t steps = 0; steps < h; ++steps) {
      const std::size_t next = (index + 1) % h;
      if (sense * (hull[next] - hull[index]).dot(axis) <= 0) break;
      index = next;
    }
  };
  for (std::size_t i = 0; i < h; ++i) {
    const Vector2d e = (hull[(i + 1) % h] - hull[i]).normalized();
    const Vector2d n(-e.y(), e.x());  // into the polygon
    advance(right, e, 1.0);
    if (i == 0) top = right;
    advance(top, n, 1.0);
    if (i == 0) left = top;
    advance(left, e, -1.0);
    const double width = (hull[right] - hull[left]).dot(e);
    const double height = (hull[top] - hull[i]).dot(n);
    const double area = (width + padding) * (height + padding);
    if (area < best_area) {
      best_area = area;
      best = {e, width, height};
    }
  }
  return best;
}

// Any unit vector perpendicular to n.
Vector3d perpendicular(const Vector3d& n) {
  const Vector3d other = std::abs(n.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
  return n.cross(other).normalized();
}

// The smallest box with a face perpendicular to n, as axes, and its (padded) volume.
std::pair<Eigen::Matrix3d, double> box_with_face_normal(const std::vector<Vector3d>& points, Vector3d n,
                                                        double padding) {
  n.normalize();
  const Vector3d u = perpendicular(n), v = n.cross(u);
  std::vector<Vector2d> projected;
  projected.reserve(points.size());
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const Vector3d& p : points) {
    projected.emplace_back(p.dot(u), p.dot(v));
    low = std::min(low, p.dot(n));
    high = std::max(high, p.dot(n));
  }
  const Rectangle r = min_area_rectangle(hull_2d(std::move(projected)), padding);
  Eigen::Matrix3d R;
  R.col(0) = (r.direction.x() * u + r.direction.y() * v).normalized();
  R.col(2) = n;
  R.col(1) = n.cross(R.col(0));
  return {R, (r.width + padding) * (r.height + padding) * (high - low + padding)};
}

double padded_volume(const std::vector<Vector3d>& points, const Eigen::Matrix3d& R, double padding) {
  Vector3d low = Vector3d::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (const Vector3d& p : points) {
    const Vector3d q = R.transpose() * p;
    low = low.cwiseMin(q);
    high = high.cwiseMax(q);
  }
  return ((high - low).array() + padding).prod();
}

// Turns R about each of its axes while the volume shrinks: a fine local search for optima no hull facet is
// flush with.
Eigen::Matrix3d polish(const std::vector<Vector3d>& points, Eigen::Matrix3d R, double padding) {
  constexpr double kDegree = 3.14159265358979323846 / 180.0;
  double best = padded_volume(points, R, padding);
  for (double step : {3.0, 1.0, 0.25, 0.05}) {
    for (bool improved = true; improved;) {
      improved = false;
      for (int axis = 0; axis < 3; ++axis) {
        for (double sign : {-1.0, 1.0}) {
          const Eigen::Matrix3d candidate =
              R * Eigen::AngleAxisd(sign * step * kDegree, Vector3d::Unit(axis)).toRotationMatrix();
          const double volume = padded_volume(points, candidate, padding);
          if (volume < best * (1.0 - 1e-9)) {
            best = volume;
            R = candidate;
            improved = true;
          }
        }
      }
    }
  }
  return R;
}

}  // namespace

namespace {

// Facet normals grouped on a grid of about 1° (sign-canonical), area-weighted, largest area first.
std::vector<FaceDirection> group_directions(qhT* qh) {
  constexpr double kCell = 0.02;  // grid step of the unit normal's components, about 1.1°
  std::map<std::array<long, 3>, FaceDirection> groups;
  for (facetT* facet = qh->facet_list; facet && facet->next; facet = facet->next) {
    Vector3d n(facet->normal[0], facet->normal[1], facet->normal[2]);
    for (int i = 0; i < 3; ++i) {
      if (n[i] != 0) {
        if (n[i] < 0) n = -n;
        break;
      }
    }
    const std::array<long, 3> key{std::lround(n.x() / kCell), std::lround(n.y() / kCell),
                                  std::lround(n.z() / kCell)};
    const double area = qh_facetarea(qh, facet);
    FaceDirection& group = groups[key];
    group.normal += area * n;
    group.area += area;
  }
  std::vector<FaceDirection> out;
  for (auto& [key, group] : groups) {
    if (group.normal.norm() > 0) out.push_back({group.normal.normalized(), group.area});
  }
  std::sort(out.begin(), out.end(),
            [](const FaceDirection& a, const FaceDirection& b) { return a.area > b.area; });
  return out;
}

}  // namespace

std::vector<Vector3d> hull_vertices(const std::vector<Vector3d>& points, std::vector<FaceDirection>* faces) {
  if (points.size() < 5) return points;
  std::vector<coordT> coordinates;
  coordinates.reserve(3 * points.size());
  for (const Vector3d& p : points) coordinates.insert(coordinates.end(), {p.x(), p.y(), p.z()});
  // qhull reports a flat or degenerate set on its error stream; it is kept out of ours.
  char* message = nullptr;
  std::size_t message_size = 0;
  FILE* errors = open_memstream(&message, &message_size);
  auto qh = std::make_unique<qhT>();
  qh_zero(qh.get(), errors);
  char options[] = "qhull Qt";
  const int failed = qh_new_qhull(qh.get(), 3, static_cast<int>(points.size()), coordinates.data(), False,
                                  options, nullptr, errors);
  std::vector<Vector3d> vertices;
  if (!failed) {
    for (vertexT* vertex = qh->vertex_list; vertex && vertex->next; vertex = vertex->next) {
      vertices.emplace_back(vertex->point[0], vertex->point[1], vertex->point[2]);
    }
    if (faces) *faces = group_directions(qh.get());
  }
  qh_freeqhull(qh.get(), !qh_ALL);
  int still_long = 0, total_long = 0;
  qh_memfreeshort(qh.get(), &still_long, &total_long);
  if (errors) std::fclose(errors);
  std::free(message);
  return failed ? points : vertices;
}

Eigen::Matrix3d minimum_volume_axes(const std::vector<Vector3d>& points, const std::vector<Vector3d>& normals,
                                    double padding) {
  // One candidate per distinct normal (n and −n give the same box).
  std::vector<Vector3d> distinct;
  for (Vector3d n : normals) {
    if (!(n.norm() > 0)) continue;
    n.normalize();
    for (int i = 0; i < 3; ++i) {
      if (n[i] != 0) {
        if (n[i] < 0) n = -n;
        break;
      }
    }
    distinct.push_back(n);
  }
  std::sort(distinct.begin(), distinct.end(), [](const Vector3d& a, const Vector3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  distinct.erase(std::unique(distinct.begin(), distinct.end(),
                             [](const Vector3d& a, const Vector3d& b) { return a.dot(b) > 1.0 - 1e-12; }),
                 distinct.end());
  // The few best flush boxes are polished: the optimum may lie near any of them.
  std::vector<std::pair<double, Eigen::Matrix3d>> candidates;
  for (const Vector3d& n : distinct) {
    const auto [R, volume] = box_with_face_normal(points, n, padding);
    candidates.emplace_back(volume, R);
  }
  const std::size_t polished = std::min<std::size_t>(kPolished, candidates.size());
  std::partial_sort(candidates.begin(), candidates.begin() + polished, candidates.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  Eigen::Matrix3d best_R = Eigen::Matrix3d::Identity();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < polished; ++c) {
    const Eigen::Matrix3d R = polish(points, candidates[c].second, padding);
    const double volume = padded_volume(points, R, padding);
    if (volume < best) {
      best = volume;
      best_R = R;
    }
  }
  return best_R;
}

double volume_along(const std::vector<Vector3d>& points, const Eigen::Matrix3d& R) {
  return padded_volume(points, R, 0.0);
}

}  // namespace cellmap::detail
