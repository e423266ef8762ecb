// SPDX-License-Identifier: Apache-2.0
#include "cellmap/collision/batch.hpp"

#include <algorithm>

#include "cellmap/common/error.hpp"
#include "projection_lanes.hpp"

namespace cellmap::collision {
namespace {

ConstraintSet empty_set(const std::vector<std::vector<Obb>>& robot_at_checkpoints,
                        const std::vector<Obb>& environment) {
  ConstraintSet set;
  set.n_checkpoints = static_cast<int>(robot_at_checkpoints.size());
  set.n_rob = robot_at_checkpoints.empty() ? 0 : static_cast<int>(robot_at_checkpoints.front().size());
  set.n_env = static_cast<int>(environment.size());
  for (std::size_t k = 0; k < robot_at_checkpoints.size(); ++k) {
    if (static_cast<int>(robot_at_checkpoints[k].size()) != set.n_rob) {
      throw Error("constraints: checkpoint " + std::to_string(k) + " has " +
                  std::to_string(robot_at_checkpoints[k].size()) + " robot boxes, checkpoint 0 has " +
                  std::to_string(set.n_rob));
    }
  }
  return set;
}

// The dense batch runs the first projections of signed_distance on kLanes environment boxes at once; the
// pairs they leave open go through signed_distance itself, so every entry equals signed_distance.
using EnvironmentLanes = BoxLanes<Double2>;
constexpr int kLanes = EnvironmentLanes::kLanes;

// The environment in blocks of kLanes (the last block padded with copies of the last box).
std::vector<EnvironmentLanes> environment_lanes(const std::vector<Obb>& environment) {
  std::vector<EnvironmentLanes> blocks((environment.size() + kLanes - 1) / kLanes);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (int l = 0; l < kLanes; ++l) {
      blocks[b].set(l, environment[std::min(b * kLanes + l, environment.size() - 1)]);
    }
  }
  return blocks;
}

// Every pair of the dense batch in order (checkpoint, robot box, environment box): the first projections of
// signed_distance on kLanes environment boxes at once, the pairs they leave open through signed_distance.
template <class Emit>
void for_each_dense(const std::vector<std::vector<Obb>>& robot_at_checkpoints,
                    const std::vector<Obb>& environment, const ConstraintSet& shape, Emit&& emit) {
  const std::vector<EnvironmentLanes> blocks = environment_lanes(environment);
  for (int k = 0; k < shape.n_checkpoints; ++k) {
    for (int r = 0; r < shape.n_rob; ++r) {
      const Obb& robot_box = robot_at_checkpoints[k][r];
      const EnvironmentLanes robot_lanes = EnvironmentLanes::broadcast(robot_box);
      for (std::size_t block = 0; block < blocks.size(); ++block) {
        ProjectionLanes<Double2> projection;
        project_twice(robot_lanes.view(), blocks[block].view(), &projection);
        const SeparatedLanes<Double2> separated(robot_lanes.view(), projection.p, projection.gap,
                                                projection.gap2);
        const int first = static_cast<int>(block) * kLanes;
        for (int l = 0; l < kLanes && first + l < shape.n_env; ++l) {
          const int e = first + l;
          emit(k, r, e,
               projection.certified[l] ? separated.lane(l) : signed_distance(robot_box, environment[e]));
        }
      }
    }
  }
}

}  // namespace

double ConstraintSet::min_distance() const {
  double best = std::numeric_limits<double>::infinity();
  for (const Constraint& c : entries) best = std::min(best, c.result.distance);
  return best;
}

bool ConstraintSet::clear(double margin) const {
  return margin < cutoff && min_distance() >= margin;
}

ConstraintSet constraints(const std::vector<std::vector<Obb>>& robot_at_checkpoints,
                          const std::vector<Obb>& environment) {
  ConstraintSet set = empty_set(robot_at_checkpoints, environment);
  set.entries.reserve(set.n_constr());
  for_each_dense(robot_at_checkpoints, environment, set, [&](int k, int r, int e, const SignedDistance& d) {
    set.entries.push_back({k, r, e, d});
  });
  return set;
}

void constraints_into(const std::vector<std::vector<Obb>>& robot_at_checkpoints,
                      const std::vector<Obb>& environment, const ConstraintArrays& out) {
  const ConstraintSet shape = empty_set(robot_at_checkpoints, environment);
  std::size_t i = 0;
  const auto put = [](double* array, std::size_t i, const Eigen::Vector3d& v) {
    if (array != nullptr) std::copy(v.data(), v.data() + 3, array + 3 * i);
  };
  for_each_dense(robot_at_checkpoints, environment, shape, [&](int, int, int, const SignedDistance& d) {
    if (out.distance != nullptr) out.distance[i] = d.distance;
    put(out.point_a, i, d.point_a);
    put(out.point_b, i, d.point_b);
    put(out.normal, i, d.normal);
    ++i;
  });
}

ConstraintSet constraints(const std::vector<std::vector<Obb>>& robot_at_checkpoints,
                          const std::vector<Obb>& environment, const BoxTree& tree, double cutoff) {
  if (tree.size() != environment.size()) {
    throw Error("constraints: the box tree holds " + std::to_string(tree.size()) +
                " boxes, the environment " + std::to_string(environment.size()));
  }
  if (!(cutoff > 0.0)) throw Error("constraints: cutoff must be > 0");
  ConstraintSet set = empty_set(robot_at_checkpoints, environment);
  set.cutoff = cutoff;
  std::vector<int> near;
  for (int k = 0; k < set.n_checkpoints; ++k) {
    for (int r = 0; r < set.n_rob; ++r) {
      const Obb& robot_box = robot_at_checkpoints[k][r];
      near.clear();
      tree.query(robot_box.center, robot_box.aabb_half_extents(), cutoff, &near);
      std::sort(near.begin(), near.end());
      for (const int e : near) set.entries.push_back({k, r, e, signed_distance(robot_box, environment[e])});
    }
  }
  return set;
}

}  // namespace cellmap::collision
