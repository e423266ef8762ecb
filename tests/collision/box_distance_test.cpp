// SPDX-License-Identifier: Apache-2.0
#include "cellmap/collision/box_distance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "epa.hpp"
#include "signed_distance.hpp"

namespace cellmap::collision {
namespace {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kExact = 1e-9;

Matrix3d rotation(double angle, const Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).matrix();
}

Obb unit_cube(const Vector3d& center) {
  return Obb(center, Vector3d(0.5, 0.5, 0.5));
}

// Several global frames: identity plus random rigid transforms; a query must be invariant under them.
std::vector<Isometry3d> global_frames() {
  std::vector<Isometry3d> frames{Isometry3d::Identity()};
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 5; ++i) {
    Isometry3d X = Isometry3d::Identity();
    X.linear() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    X.translation() = Vector3d(u(rng), u(rng), u(rng)) * 10.0;
    frames.push_back(X);
  }
  return frames;
}

struct Expected {
  double distance;
  Vector3d point_a;  // in the identity frame; checked only when `check_points`
  Vector3d point_b;
  bool check_points;
};

void expect_in_all_frames(const Obb& a, const Obb& b, const Expected& expected) {
  for (const Isometry3d& X : global_frames()) {
    const Obb ga = a.transformed(X);
    const Obb gb = b.transformed(X);
    const SignedDistance d = signed_distance(ga, gb);
    EXPECT_NEAR(d.distance, expected.distance, kExact);
    EXPECT_NEAR(d.normal.norm(), 1.0, 1e-12);
    EXPECT_LT((d.point_b - (d.point_a + d.distance * d.normal)).norm(), kExact);
    if (expected.check_points) {
      EXPECT_LT((d.point_a - X * expected.point_a).norm(), kExact) << d.point_a.transpose();
      EXPECT_LT((d.point_b - X * expected.point_b).norm(), kExact) << d.point_b.transpose();
    }
    // The witness points lie on (or in) their boxes.
    EXPECT_TRUE(to_box(ga).contains(d.point_a, 1e-9));
    EXPECT_TRUE(to_box(gb).contains(d.point_b, 1e-9));
    // Swapping A and B gives the same distance.
    EXPECT_NEAR(signed_distance(gb, ga).distance, expected.distance, kExact);
  }
}

TEST(BoxDistanceTest, UnitCubesAlongEachAxis) {
  for (int axis = 0; axis < 3; ++axis) {
    for (const auto& [offset, distance] : std::vector<std::pair<double, double>>{
             {2.0, 1.0}, {1.01, 0.01}, {1.0, 0.0}, {0.99, -0.01}, {0.0, -1.0}}) {
      SCOPED_TRACE("axis " + std::to_string(axis) + " offset " + std::to_string(offset));
      const Obb a = unit_cube(Vector3d::Zero());
      const Obb b = unit_cube(offset * Vector3d::Unit(axis));
      expect_in_all_frames(a, b, {distance, {}, {}, false});
      const SignedDistance d = signed_distance(a, b);
      if (offset > 0.0) {
        EXPECT_NEAR(d.normal.dot(Vector3d::Unit(axis)), 1.0, 1e-12);
      }
    }
  }
}

TEST(BoxDistanceTest, FclBug508CaseUnitCubesFourApartOnY) {
  // FCL's libccd solver answers 3.16228 here (fcl#508); the true distance is 3.
  expect_in_all_frames(unit_cube(Vector3d::Zero()), unit_cube(Vector3d(0, 4, 0)), {3.0, {}, {}, false});
}

TEST(BoxDistanceTest, VertexVertexKnownAnswerWithWitnessPoints) {
  const Obb a(Vector3d::Zero(), Vector3d(3, 5, 1));
  const Obb b(Vector3d(25, 20, 5), Vector3d(1, 1, 1));
  expect_in_all_frames(a, b, {std::sqrt(21.0 * 21 + 14 * 14 + 3 * 3), {3, 5, 1}, {24, 19, 4}, true});
}

TEST(BoxDistanceTest, RotatedCubeCornerTowardsAFace) {
  // A unit cube turned 45 degrees about z and then tilted so that one corner points along -x: its lowest
  // x is the centre minus half the space diagonal sqrt(3)/2.
  const Matrix3d R = Eigen::Quaterniond::FromTwoVectors(Vector3d(-1, -1, -1).normalized(), -Vector3d::UnitX())
                         .toRotationMatrix();
  const double reach = std::sqrt(3.0) / 2;
  const Obb a = unit_cube(Vector3d::Zero());
  for (const double gap : {0.5, 1e-3, 0.0, -1e-3, -0.2}) {
    SCOPED_TRACE(gap);
    const Obb b(Vector3d(0.5 + reach + gap, 0.1, -0.2), Vector3d(0.5, 0.5, 0.5), R);
    expect_in_all_frames(a, b, {gap, {0.5, 0.1, -0.2}, {0.5 + gap, 0.1, -0.2}, true});
  }
}

TEST(BoxDistanceTest, TiltedKissingEdgeOnFace) {
  // A cube rotated 45 degrees about y rests on an edge: its lowest point is sqrt(2)/2 below its centre.
  const Obb ground(Vector3d(0, 0, -0.5), Vector3d(2, 2, 0.5));
  const Matrix3d R = rotation(M_PI / 4, Vector3d::UnitY());
  for (const double gap : {0.3, 1e-9, 0.0, -1e-9, -0.05}) {
    SCOPED_TRACE(gap);
    const Obb cube(Vector3d(0.2, 0.1, std::sqrt(0.5) + gap), Vector3d(0.5, 0.5, 0.5), R);
    expect_in_all_frames(ground, cube, {gap, {}, {}, false});
    const SignedDistance d = signed_distance(ground, cube);
    EXPECT_NEAR(d.normal.z(), 1.0, 1e-9);
    EXPECT_NEAR(d.point_a.x(), 0.2, 1e-9);  // the contact edge runs along y at x = 0.2
  }
}

TEST(BoxDistanceTest, EdgeEdgeCrossed) {
  // Two long bars crossing at right angles, each turned 45 degrees about its length so edges face each other.
  const Obb a(Vector3d::Zero(), Vector3d(2, 0.5, 0.5), rotation(M_PI / 4, Vector3d::UnitX()));
  const double reach = std::sqrt(0.5);
  for (const double gap : {1.0, 0.01, -0.01}) {
    const Obb b(Vector3d(0.3, -0.4, 2 * reach + gap), Vector3d(0.5, 2, 0.5),
                rotation(M_PI / 4, Vector3d::UnitY()));
    expect_in_all_frames(a, b, {gap, {0.3, 0, reach}, {0.3, 0, reach + gap}, true});
  }
}

// A bar along x turned 45 degrees about its length (an edge up, at z = sqrt(1/2)) and a bar above it along
// (cos angle, sin angle, 0) turned the same way (an edge down), its centre above the point (0.3, 0): the two
// edges are skew lines `gap` apart in z, closest at (0.3, 0).
void expect_crossing_edges(double angle, double gap, bool check_points) {
  const double reach = std::sqrt(0.5);
  const Obb a(Vector3d::Zero(), Vector3d(2, 0.5, 0.5), rotation(M_PI / 4, Vector3d::UnitX()));
  const Obb b(Vector3d(0.3, 0, 2 * reach + gap), Vector3d(1.5, 0.5, 0.5),
              rotation(angle, Vector3d::UnitZ()) * rotation(M_PI / 4, Vector3d::UnitX()));
  expect_in_all_frames(a, b, {gap, {0.3, 0, reach}, {0.3, 0, reach + gap}, check_points});
}

TEST(BoxDistanceTest, EdgeEdgeAtAnglesDownToParallel) {
  for (const double angle : {1.2, 0.3, 1e-2, 1e-3}) {
    for (const double gap : {0.7, 1e-3, 1e-9, 1e-12, 0.0}) {
      SCOPED_TRACE(testing::Message() << "angle " << angle << " gap " << gap);
      expect_crossing_edges(angle, gap, true);
    }
  }
  // Nearly parallel (sin^2 of the angle at or below 1e-9) and parallel: the closest points are not unique
  // (or barely), the distance is. The projections creep along such edges; they must not stop early.
  for (const double angle : {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 0.0}) {
    for (const double gap : {0.7, 1e-3, 1e-6}) {
      SCOPED_TRACE(testing::Message() << "angle " << angle << " gap " << gap);
      expect_crossing_edges(angle, gap, false);
    }
  }
  // Touching, down to 1e-6 rad: nearer to parallel the separating axes that give the depth lose up to ~1e-8 m
  // (a nearly degenerate edge-edge axis).
  for (const double angle : {1e-4, 1e-5, 1e-6, 0.0}) {
    SCOPED_TRACE(testing::Message() << "angle " << angle);
    expect_crossing_edges(angle, 0.0, false);
  }
}

TEST(BoxDistanceTest, DegenerateThinBoxesCrossing) {
  // Boxes with zero half extents: segments (one free coordinate, all edge) and a plate.
  const Obb along_x(Vector3d::Zero(), Vector3d(2, 0, 0));
  for (const double angle : {M_PI / 2, 0.4, 1e-3}) {
    SCOPED_TRACE(angle);
    const Obb segment(Vector3d(0.3, 0, 1.0), Vector3d(1, 0, 0), rotation(angle, Vector3d::UnitZ()));
    expect_in_all_frames(along_x, segment, {1.0, {0.3, 0, 0}, {0.3, 0, 1.0}, true});
    const Obb touching(Vector3d(0.3, 0, 0), Vector3d(1, 0, 0), rotation(angle, Vector3d::UnitZ()));
    expect_in_all_frames(along_x, touching, {0.0, {}, {}, false});
  }
  // A plate (zero thickness) under a tilted segment whose low end lies over the plate.
  const Obb plate(Vector3d::Zero(), Vector3d(1, 1, 0));
  const Matrix3d tilt = rotation(std::atan2(0.5, 2.0), -Vector3d::UnitY());  // along (2, 0, 0.5)/|.|
  const Obb tilted(Vector3d(1.0, 0.2, 0.3), Vector3d(std::hypot(2.0, 0.5) / 2, 0, 0), tilt);
  // The segment runs from (0, 0.2, 0.05) to (2, 0.2, 0.55): its low end lies over the plate at 0.05.
  expect_in_all_frames(plate, tilted, {0.05, {0, 0.2, 0}, {0, 0.2, 0.05}, true});
}

TEST(BoxDistanceTest, BarEndTowardsAFace) {
  // A bar turned 45 degrees about its length, then tilted by 0.2 rad about y, above a wide slab: its lowest
  // point is the end of its lowest edge, the vertex (hx, -hy, -hz), hx sin(0.2) + sqrt(2) hy cos(0.2) below
  // its centre.
  const Obb slab(Vector3d(0, 0, -0.5), Vector3d(3, 3, 0.5));
  const Matrix3d R = rotation(0.2, Vector3d::UnitY()) * rotation(M_PI / 4, Vector3d::UnitX());
  const double drop = 1.0 * std::sin(0.2) + std::sqrt(2.0) * 0.1 * std::cos(0.2);
  for (const double gap : {0.4, 1e-9, 0.0}) {
    SCOPED_TRACE(gap);
    const Obb bar(Vector3d(0.1, -0.3, drop + gap), Vector3d(1.0, 0.1, 0.1), R);
    const Vector3d lowest = bar.center + R * Vector3d(1.0, -0.1, -0.1);
    expect_in_all_frames(slab, bar, {gap, {lowest.x(), lowest.y(), 0.0}, lowest, true});
  }
}

TEST(BoxDistanceTest, IdenticalBoxesPenetrateByTheirSmallestWidth) {
  const Obb a(Vector3d(1, 2, 3), Vector3d(0.3, 0.1, 0.7), rotation(0.4, Vector3d(1, 2, 3)));
  expect_in_all_frames(a, a, {-0.2, {}, {}, false});
  EXPECT_NEAR(epa_penetration(a, a).distance, -0.2, kExact);
  EXPECT_NEAR(epa_penetration(unit_cube(Vector3d::Zero()), unit_cube(Vector3d::Zero())).distance, -1.0,
              kExact);
}

TEST(BoxDistanceTest, DegenerateBoxesStayFinite) {
  const Obb point(Vector3d(1, 0, 0), Vector3d::Zero());
  const Obb flat(Vector3d::Zero(), Vector3d(0.5, 0.5, 0.0));
  const SignedDistance d = signed_distance(point, flat);
  EXPECT_NEAR(d.distance, 0.5, kExact);
  const SignedDistance same = signed_distance(point, point);
  EXPECT_EQ(same.distance, 0.0);
  EXPECT_TRUE(same.normal.allFinite() && same.point_a.allFinite() && same.point_b.allFinite());
  const SignedDistance inside = signed_distance(Obb(Vector3d(0.1, 0.2, 0), Vector3d::Zero()), flat);
  EXPECT_NEAR(inside.distance, 0.0, kExact);
}

TEST(BoxDistanceTest, SeparatingAxesAgreeWithSignedDistanceSign) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> h(0.05, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const Obb a(Vector3d(u(rng), u(rng), u(rng)), Vector3d(h(rng), h(rng), h(rng)),
                Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix());
    const Obb b(Vector3d(u(rng), u(rng), u(rng)) * 2.0, Vector3d(h(rng), h(rng), h(rng)),
                Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix());
    const SignedDistance d = signed_distance(a, b);
    ASSERT_TRUE(std::isfinite(d.distance));
    if (d.distance > 1e-5) {
      EXPECT_FALSE(overlap(a, b));
      EXPECT_TRUE(overlap(a, b, d.distance + 1e-9));  // no axis separates by more than the distance
    }
    if (d.distance < -1e-9) {
      EXPECT_TRUE(overlap(a, b));
      // EPA (independent of the separating axes) finds the same depth.
      const SignedDistance epa = epa_penetration(a, b);
      EXPECT_NEAR(epa.distance, d.distance, 1e-9);
    }
    // Separating-axis margin semantics: separated by >= margin on some axis implies distance >= margin.
    if (!overlap(a, b, 0.1)) {
      EXPECT_GE(d.distance, 0.1 - 1e-12);
    }
  }
}

// signed_distance runs its AVX build where the CPU has AVX; the baseline build that other CPUs run must give
// the very same numbers, on separated and overlapping pairs alike.
TEST(BoxDistanceTest, BaselineBuildGivesTheSameBits) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (!__builtin_cpu_supports("avx")) GTEST_SKIP() << "no AVX here: signed_distance is the baseline build";
#else
  GTEST_SKIP() << "signed_distance has only the baseline build here";
#endif
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> h(0.0, 1.0);
  const auto box = [&](double spread) {
    return Obb(Vector3d(u(rng), u(rng), u(rng)) * spread, Vector3d(h(rng), h(rng), h(rng)),
               Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix());
  };
  int overlapping = 0;
  for (int i = 0; i < 20000; ++i) {
    const Obb a = box(1.0);
    const Obb b = box(i % 2 == 0 ? 1.0 : 3.0);
    const SignedDistance ours = signed_distance(a, b);
    const SignedDistance baseline = signed_distance_baseline(a, b);
    overlapping += ours.distance < 0.0;
    ASSERT_EQ(ours.distance, baseline.distance) << "pair " << i;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(ours.point_a[k], baseline.point_a[k]) << "pair " << i;
      ASSERT_EQ(ours.point_b[k], baseline.point_b[k]) << "pair " << i;
      ASSERT_EQ(ours.normal[k], baseline.normal[k]) << "pair " << i;
    }
  }
  EXPECT_GT(overlapping, 2000);  // both branches of the query ran
  EXPECT_LT(overlapping, 18000);
}

}  // namespace
}  // namespace cellmap::collision
