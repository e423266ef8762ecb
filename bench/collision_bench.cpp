// Collision benchmarks against FCL 0.7 (GST_INDEP, the solver that gets box distances right), same run.
#include <benchmark/benchmark.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <random>
#include <vector>

#include "cellmap/collision/box_distance.hpp"
#include "ratio_report.hpp"

namespace {

using cellmap::collision::Obb;
using Eigen::Vector3d;

// A fixed set of 1024 random box pairs, cycled through by every benchmark: `separated` ones for distance (the
// query both libraries answer; FCL's distance returns -1 for overlaps) and `mixed` ones (about 1/3
// overlapping).
struct Pairs {
  std::vector<Obb> a, b;
  std::vector<fcl::Transform3d> Xa, Xb;
  std::vector<fcl::Boxd> fa, fb;
};

Pairs make_pairs(bool separated_only) {
  {
    Pairs p;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_real_distribution<double> h(0.02, 1.0);
    const auto box = [&](double spread) {
      return Obb(Vector3d(u(rng), u(rng), u(rng)) * spread, Vector3d(h(rng), h(rng), h(rng)),
                 Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix());
    };
    const auto pose = [](const Obb& o) {
      fcl::Transform3d X = fcl::Transform3d::Identity();
      X.linear() = o.rotation;
      X.translation() = o.center;
      return X;
    };
    while (p.a.size() < 1024) {
      const Obb a = box(1.0);
      const Obb b = box(3.0);
      if (separated_only && cellmap::collision::overlap(a, b)) continue;
      p.a.push_back(a);
      p.b.push_back(b);
      p.Xa.push_back(pose(p.a.back()));
      p.Xb.push_back(pose(p.b.back()));
      p.fa.emplace_back(2 * p.a.back().half_extents);
      p.fb.emplace_back(2 * p.b.back().half_extents);
    }
    return p;
  }
}

const Pairs& separated() {
  static const Pairs p = make_pairs(true);
  return p;
}

const Pairs& mixed() {
  static const Pairs p = make_pairs(false);
  return p;
}

void BM_BoxDistanceOurs(benchmark::State& state) {
  const Pairs& p = separated();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(cellmap::collision::signed_distance(p.a[i], p.b[i]));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_BoxDistanceOurs);

void BM_BoxDistanceFcl(benchmark::State& state) {
  const Pairs& p = separated();
  fcl::DistanceRequestd request(true, false);
  request.gjk_solver_type = fcl::GST_INDEP;
  std::size_t i = 0;
  for (auto _ : state) {
    fcl::DistanceResultd result;
    benchmark::DoNotOptimize(fcl::distance(&p.fa[i], p.Xa[i], &p.fb[i], p.Xb[i], request, result));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_BoxDistanceFcl);

void BM_OverlapOurs(benchmark::State& state) {
  const Pairs& p = mixed();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(cellmap::collision::overlap(p.a[i], p.b[i]));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_OverlapOurs);

// The exact separating-axis depth (all 15 axes, normalised): the first step of every signed distance.
void BM_SeparatingAxisDepthOurs(benchmark::State& state) {
  const Pairs& p = separated();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(cellmap::collision::separating_axis_depth(p.a[i], p.b[i]));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_SeparatingAxisDepthOurs);

// GJK alone (no separating-axis certificate) on the separated set.
void BM_GjkDistanceOurs(benchmark::State& state) {
  const Pairs& p = separated();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(cellmap::collision::gjk_distance(p.a[i], p.b[i]));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_GjkDistanceOurs);

// Signed distance on the mixed set: overlapping pairs add the separating-axis depth and the witness search.
void BM_SignedDistanceMixedOurs(benchmark::State& state) {
  const Pairs& p = mixed();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(cellmap::collision::signed_distance(p.a[i], p.b[i]));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_SignedDistanceMixedOurs);

void BM_OverlapFcl(benchmark::State& state) {
  const Pairs& p = mixed();
  fcl::CollisionRequestd request;
  request.gjk_solver_type = fcl::GST_INDEP;
  std::size_t i = 0;
  for (auto _ : state) {
    fcl::CollisionResultd result;
    benchmark::DoNotOptimize(fcl::collide(&p.fa[i], p.Xa[i], &p.fb[i], p.Xb[i], request, result));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_OverlapFcl);

}  // namespace

int main(int argc, char** argv) {
  return cellmap::bench::run_and_report(argc, argv,
                                        {{"box-box distance", "BM_BoxDistanceOurs", "BM_BoxDistanceFcl"},
                                         {"obb overlap", "BM_OverlapOurs", "BM_OverlapFcl"}});
}
