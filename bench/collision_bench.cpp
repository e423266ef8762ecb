// SPDX-License-Identifier: Apache-2.0
// Collision benchmarks against FCL 0.7 (GST_INDEP, the solver that gets box distances right), same run.
#include <benchmark/benchmark.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <random>
#include <vector>

#include "cellmap/collision/batch.hpp"
#include "cellmap/collision/box_distance.hpp"
#include "cellmap/collision/box_tree.hpp"
#include "cellmap/planning/path_check.hpp"
#include "gjk.hpp"
#include "ratio_report.hpp"
#include "separating_axes.hpp"

namespace {

using cellmap::collision::Obb;
using Eigen::Vector3d;

// A fixed set of 1024 random box pairs, cycled through by every benchmark: `separated` ones for distance (the
// query both libraries answer; FCL's distance returns -1 for overlaps) and `mixed` ones (46 of the 1024
// overlap: b's centre is spread three times wider than a's).
struct Pairs {
  std::vector<Obb> a, b;
  std::vector<fcl::Transform3d> Xa, Xb;
  std::vector<fcl::Boxd> fa, fb;
};

fcl::Transform3d fcl_pose(const Obb& o) {
  fcl::Transform3d X = fcl::Transform3d::Identity();
  X.linear() = o.rotation;
  X.translation() = o.center;
  return X;
}

Pairs make_pairs(bool separated_only) {
  Pairs p;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> h(0.02, 1.0);
  const auto box = [&](double spread) {
    return Obb(Vector3d(u(rng), u(rng), u(rng)) * spread, Vector3d(h(rng), h(rng), h(rng)),
               Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix());
  };
  while (p.a.size() < 1024) {
    const Obb a = box(1.0);
    const Obb b = box(3.0);
    if (separated_only && cellmap::collision::overlap(a, b)) continue;
    p.a.push_back(a);
    p.b.push_back(b);
    p.Xa.push_back(fcl_pose(a));
    p.Xb.push_back(fcl_pose(b));
    p.fa.emplace_back(2 * a.half_extents);
    p.fb.emplace_back(2 * b.half_extents);
  }
  return p;
}

const Pairs& separated() {
  static const Pairs p = make_pairs(true);
  return p;
}

const Pairs& mixed() {
  static const Pairs p = make_pairs(false);
  return p;
}

// Runs `query(pairs, i)` on pair after pair, cycling through the 1024.
template <typename Query>
void cycle(benchmark::State& state, const Pairs& pairs, Query query) {
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(query(pairs, i));
    i = (i + 1) & 1023;
  }
}

void BM_BoxDistanceOurs(benchmark::State& state) {
  cycle(state, separated(),
        [](const Pairs& p, std::size_t i) { return cellmap::collision::signed_distance(p.a[i], p.b[i]); });
}
BENCHMARK(BM_BoxDistanceOurs);

void BM_BoxDistanceFcl(benchmark::State& state) {
  fcl::DistanceRequestd request(true, false);
  request.gjk_solver_type = fcl::GST_INDEP;
  cycle(state, separated(), [&](const Pairs& p, std::size_t i) {
    fcl::DistanceResultd result;
    return fcl::distance(&p.fa[i], p.Xa[i], &p.fb[i], p.Xb[i], request, result);
  });
}
BENCHMARK(BM_BoxDistanceFcl);

void BM_OverlapOurs(benchmark::State& state) {
  cycle(state, mixed(),
        [](const Pairs& p, std::size_t i) { return cellmap::collision::overlap(p.a[i], p.b[i]); });
}
BENCHMARK(BM_OverlapOurs);

// The exact separating-axis depth (all 15 axes, normalised): the first step of every signed distance.
void BM_SeparatingAxisDepthOurs(benchmark::State& state) {
  cycle(state, separated(), [](const Pairs& p, std::size_t i) {
    return cellmap::collision::separating_axis_depth(p.a[i], p.b[i]);
  });
}
BENCHMARK(BM_SeparatingAxisDepthOurs);

// GJK alone (no separating-axis certificate) on the separated set.
void BM_GjkDistanceOurs(benchmark::State& state) {
  cycle(state, separated(),
        [](const Pairs& p, std::size_t i) { return cellmap::collision::gjk_distance(p.a[i], p.b[i]); });
}
BENCHMARK(BM_GjkDistanceOurs);

// Signed distance on the mixed set: overlapping pairs add the separating-axis depth and the witness search.
void BM_SignedDistanceMixedOurs(benchmark::State& state) {
  cycle(state, mixed(),
        [](const Pairs& p, std::size_t i) { return cellmap::collision::signed_distance(p.a[i], p.b[i]); });
}
BENCHMARK(BM_SignedDistanceMixedOurs);

void BM_OverlapFcl(benchmark::State& state) {
  fcl::CollisionRequestd request;
  request.gjk_solver_type = fcl::GST_INDEP;
  cycle(state, mixed(), [&](const Pairs& p, std::size_t i) {
    fcl::CollisionResultd result;
    return fcl::collide(&p.fa[i], p.Xa[i], &p.fb[i], p.Xb[i], request, result);
  });
}
BENCHMARK(BM_OverlapFcl);

// Batch: a gantry (bridge, carriage, ram, 2 boxes each = 6 robot boxes) drives a B-spline path through a
// 4 m x 4 m cell sampled at 100 checkpoints, against n_env random boxes standing on the floor.
struct BatchScene {
  std::vector<std::vector<Obb>> robot;  // [checkpoint][robot box]
  std::vector<Obb> environment;
};

BatchScene make_batch_scene(int n_env) {
  using cellmap::LinkBox;
  const auto at = [](double x, double y, double z) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = Vector3d(x, y, z);
    return X;
  };
  const cellmap::collision::RobotBoxes gantry(
      cellmap::Robot::gantry(Vector3d(0, 0, 0), Vector3d(4, 4, 1.5)),
      {LinkBox{"bridge", at(0, 2, 2.0), Vector3d(0.1, 2.0, 0.1)},
       LinkBox{"bridge", at(0, 0, 1.9), Vector3d(0.1, 0.1, 0.1)},
       LinkBox{"carriage", at(0, 0, 1.8), Vector3d(0.15, 0.15, 0.1)},
       LinkBox{"carriage", at(0, 0.2, 1.8), Vector3d(0.05, 0.05, 0.05)},
       LinkBox{"ram", at(0, 0, 0.6), Vector3d(0.06, 0.06, 0.5)},
       LinkBox{"ram", at(0, 0, 0.0), Vector3d(0.08, 0.08, 0.05)}});
  const cellmap::planning::BSplinePath path(
      {Vector3d(0.3, 0.3, 1.0), Vector3d(1.5, 3.5, 0.6), Vector3d(2.5, 0.5, 0.4), Vector3d(3.7, 3.7, 1.0)});
  BatchScene scene;
  scene.robot = cellmap::planning::place_along(gantry, path, 100);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> xy(0.0, 4.0), h(0.05, 0.3), yaw(0.0, M_PI);
  for (int i = 0; i < n_env; ++i) {
    const Vector3d half(h(rng), h(rng), h(rng));
    scene.environment.emplace_back(Vector3d(xy(rng), xy(rng), half.z()), half,
                                   Eigen::AngleAxisd(yaw(rng), Vector3d::UnitZ()).toRotationMatrix());
  }
  return scene;
}

// The environment sizes the batch benchmarks run at.
void environment_sizes(benchmark::internal::Benchmark* b) {
  b->ArgName("n_env")->Unit(benchmark::kMicrosecond);
  for (int n : {10, 50, 200, 1000}) b->Arg(n);
}

void BM_BatchDense(benchmark::State& state) {
  const BatchScene scene = make_batch_scene(static_cast<int>(state.range(0)));
  for (auto _ : state)
    benchmark::DoNotOptimize(cellmap::collision::constraints(scene.robot, scene.environment));
  state.counters["n_constr"] = 6.0 * 100 * state.range(0);
}
BENCHMARK(BM_BatchDense)->Apply(environment_sizes);

// Broad phase with a 0.3 m cutoff; the tree is built once per environment version, outside the loop.
void BM_BatchBroadPhase(benchmark::State& state) {
  const BatchScene scene = make_batch_scene(static_cast<int>(state.range(0)));
  const cellmap::collision::BoxTree tree(scene.environment);
  std::size_t evaluated = 0;
  for (auto _ : state) {
    const auto set = cellmap::collision::constraints(scene.robot, scene.environment, tree, 0.3);
    evaluated = set.entries.size();
    benchmark::DoNotOptimize(set);
  }
  state.counters["evaluated"] = static_cast<double>(evaluated);
}
BENCHMARK(BM_BatchBroadPhase)->Apply(environment_sizes);

void BM_BoxTreeBuild(benchmark::State& state) {
  const BatchScene scene = make_batch_scene(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(cellmap::collision::BoxTree(scene.environment));
}
BENCHMARK(BM_BoxTreeBuild)->ArgName("n_env")->Arg(1000)->Unit(benchmark::kMicrosecond);

// FCL doing the same dense batch: one fcl::distance per pair (overlapping pairs return -1 there, cheaper).
void BM_BatchFcl(benchmark::State& state) {
  const BatchScene scene = make_batch_scene(static_cast<int>(state.range(0)));
  std::vector<fcl::Boxd> env_shapes;
  std::vector<fcl::Transform3d> env_poses;
  for (const Obb& o : scene.environment) {
    env_shapes.emplace_back(2 * o.half_extents);
    env_poses.push_back(fcl_pose(o));
  }
  fcl::DistanceRequestd request(true, false);
  request.gjk_solver_type = fcl::GST_INDEP;
  for (auto _ : state) {
    double sum = 0;
    for (const auto& boxes : scene.robot) {
      for (const Obb& r : boxes) {
        const fcl::Boxd shape(2 * r.half_extents);
        const fcl::Transform3d X = fcl_pose(r);
        for (std::size_t e = 0; e < env_shapes.size(); ++e) {
          fcl::DistanceResultd result;
          sum += fcl::distance(&shape, X, &env_shapes[e], env_poses[e], request, result);
        }
      }
    }
    benchmark::DoNotOptimize(sum);
  }
}
BENCHMARK(BM_BatchFcl)->ArgName("n_env")->Arg(50)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  return cellmap::bench::run_and_report(
      argc, argv,
      {{"box-box distance", "BM_BoxDistanceOurs", "BM_BoxDistanceFcl"},
       {"obb overlap", "BM_OverlapOurs", "BM_OverlapFcl"},
       {"batch 6x50x100 distance", "BM_BatchDense/n_env:50", "BM_BatchFcl/n_env:50"},
       {"broad phase 6x50x100", "BM_BatchBroadPhase/n_env:50", "BM_BatchDense/n_env:50"},
       {"broad phase 6x1000x100", "BM_BatchBroadPhase/n_env:1000", "BM_BatchDense/n_env:1000"}});
}
