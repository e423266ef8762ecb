#include "mutual_projections.hpp"

namespace cellmap::collision::mutual_projections_detail {
namespace {

// The feature of a box holding a point on its surface: bit k set when |x_k| < h_k (coordinate k free).
// An edge point has one free coordinate, a face point two.
int free_coordinates(const double* x, const double* h) {
  return int(std::abs(x[0]) < h[0]) | int(std::abs(x[1]) < h[1]) << 1 | int(std::abs(x[2]) < h[2]) << 2;
}
constexpr int kEdgeDirection[8] = {-1, 0, 1, -1, 2, -1, -1, -1};  // the free coordinate of an edge point
constexpr int kFaceNormal[8] = {-1, -1, -1, 2, -1, 1, 0, -1};     // the fixed coordinate of a face point

// Below this |cos| (resp. sin^2) an edge counts as parallel to a face (resp. an edge): the closest points are
// then not unique and the projections settle on one pair by themselves.
constexpr double kParallel = 1e-9;

// p on A's edge i, y on B's edge j: y moves to the point of its edge closest to A's edge line (clamped).
bool step_to_crossing_edges(const double* hb, const double* R, const double* t, const double* p, int i, int j,
                            double* y) {
  const double* d = R + 3 * j;  // B's edge direction in A's frame
  const double c = d[i];
  const double sin2 = 1.0 - c * c;
  if (!(sin2 > kParallel)) return false;
  // Lines a0 + alpha e_i (a0 = p with p_i = 0) and b0 + beta d (b0 = B's edge centre); r = a0 - b0.
  double y0[3] = {y[0], y[1], y[2]};
  y0[j] = 0.0;
  double r[3];
  b_to_a(R, t, y0, r);
  for (int k = 0; k < 3; ++k) r[k] = (k == i ? 0.0 : p[k]) - r[k];
  const double dr = d[0] * r[0] + d[1] * r[1] + d[2] * r[2];
  const double alpha = (c * dr - r[i]) / sin2;
  const double moved = clamp(dr + alpha * c, hb[j]);
  if (moved == y[j]) return false;
  y[j] = moved;
  return true;
}

// x_k on an edge of its box (free coordinate k, half extent h) facing the other box's face, whose outward
// normal has component `slope` along the edge: the edge's end nearest the face plane, unless parallel.
bool step_to_edge_end(double slope, double h, double* x_k) {
  if (!(std::abs(slope) > kParallel)) return false;
  *x_k = slope > 0.0 ? -h : h;
  return true;
}

}  // namespace

bool jump_on_b(const double* ha, const double* hb, const double* R, const double* t, const double* p,
               double* y) {
  const int j = kEdgeDirection[free_coordinates(y, hb)];
  if (j < 0) return false;
  const int p_free = free_coordinates(p, ha);
  const int i = kEdgeDirection[p_free];
  if (i >= 0) return step_to_crossing_edges(hb, R, t, p, i, j, y);
  const int face = kFaceNormal[p_free];
  if (face < 0 || p[face] == 0.0) return false;
  // A's face normal is sign(p_face) e_face; B's edge direction is R.col(j).
  return step_to_edge_end(p[face] > 0.0 ? R[face + 3 * j] : -R[face + 3 * j], hb[j], &y[j]);
}

bool jump_on_a(const double* ha, const double* hb, const double* R, const double* y, double* p) {
  const int i = kEdgeDirection[free_coordinates(p, ha)];
  if (i < 0) return false;
  const int face = kFaceNormal[free_coordinates(y, hb)];
  if (face < 0 || y[face] == 0.0) return false;
  // B's face normal in A's frame is sign(y_face) R.col(face); A's edge direction is e_i.
  return step_to_edge_end(y[face] > 0.0 ? R[i + 3 * face] : -R[i + 3 * face], ha[i], &p[i]);
}

}  // namespace cellmap::collision::mutual_projections_detail
