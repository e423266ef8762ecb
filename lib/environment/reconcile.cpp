// SPDX-License-Identifier: Apache-2.0
#include "cellmap/environment/reconcile.hpp"

#include <algorithm>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

double iou(const Region& a, const Region& b) {
  const double common = a.intersection(b).volume();
  const double both = a.volume() + b.volume() - common;
  return both > 0 ? common / both : 0.0;
}

bool within_tolerance(const Box& a, const Box& b, const ReconcileParams& options) {
  return (a.center - b.center).norm() < options.position_tolerance &&
         (a.half_extents - b.half_extents).cwiseAbs().maxCoeff() < options.position_tolerance &&
         a.rotation.angularDistance(b.rotation) < options.rotation_tolerance;
}

}  // namespace

Region bounds_of(const Box& box) {
  const Eigen::Vector3d half = box.rotation.toRotationMatrix().cwiseAbs() * box.half_extents;
  return {box.center - half, box.center + half};
}

bool box_inside(const Box& inner, const Box& outer, double tolerance) {
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d sign((corner & 1) ? 1 : -1, (corner & 2) ? 1 : -1, (corner & 4) ? 1 : -1);
    if (!outer.contains(inner.center + inner.rotation * sign.cwiseProduct(inner.half_extents), tolerance)) {
      return false;
    }
  }
  return true;
}

std::vector<std::uint64_t> boxes_touched(const std::vector<Box>& previous,
                                         const std::vector<Eigen::Vector3d>& changed_C, double min_share) {
  std::vector<std::uint64_t> ids;
  for (const Box& box : previous) {
    const Region bounds = bounds_of(box);
    const auto inside = std::count_if(changed_C.begin(), changed_C.end(), [&](const Eigen::Vector3d& p) {
      return bounds.contains(p) && box.contains(p);
    });
    if (inside > 0 && static_cast<double>(inside) >= min_share * static_cast<double>(box.points)) {
      ids.push_back(box.id);
    }
  }
  return ids;
}

namespace {

// The re-segmented boxes that neither a kept box nor a bigger re-segmented one holds, largest first, so a
// sliver inside a bigger new box (a face segment the merge left apart) is the one dropped.
std::vector<const Box*> candidates_of(const std::vector<Box>& resegmented,
                                      const std::vector<const Box*>& kept, double redundant_tolerance) {
  std::vector<const Box*> by_volume;
  for (const Box& box : resegmented) by_volume.push_back(&box);
  std::stable_sort(by_volume.begin(), by_volume.end(),
                   [](const Box* a, const Box* b) { return a->volume() > b->volume(); });
  std::vector<const Box*> candidates;
  for (const Box* box : by_volume) {
    const auto covers = [&](const Box* other) { return box_inside(*box, *other, redundant_tolerance); };
    if (std::none_of(kept.begin(), kept.end(), covers) &&
        std::none_of(candidates.begin(), candidates.end(), covers)) {
      candidates.push_back(box);
    }
  }
  return candidates;
}

// Pairs (candidate, old box) overlapping by at least min_overlap, best overlap first; ties broken by index
// so the result is deterministic.
std::vector<std::pair<std::size_t, std::size_t>> by_overlap(const std::vector<const Box*>& candidates,
                                                            const std::vector<const Box*>& old_in_scope,
                                                            double min_overlap) {
  std::vector<std::tuple<double, std::size_t, std::size_t>> scored;
  for (std::size_t n = 0; n < candidates.size(); ++n) {
    for (std::size_t o = 0; o < old_in_scope.size(); ++o) {
      const double overlap = iou(bounds_of(*candidates[n]), bounds_of(*old_in_scope[o]));
      if (overlap >= min_overlap) scored.emplace_back(-overlap, n, o);
    }
  }
  std::sort(scored.begin(), scored.end());
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (const auto& [negative_overlap, n, o] : scored) pairs.emplace_back(n, o);
  return pairs;
}

void sort_by_id(Reconciled& out) {
  const auto by_id = [](const Box& a, const Box& b) { return a.id < b.id; };
  std::sort(out.boxes.begin(), out.boxes.end(), by_id);
  std::sort(out.modified.begin(), out.modified.end(), by_id);
  std::sort(out.removed.begin(), out.removed.end());
}

}  // namespace

Reconciled reconcile(const std::vector<Box>& previous, const std::vector<std::uint64_t>& in_scope,
                     const std::vector<Box>& resegmented, std::uint64_t next_id,
                     const ReconcileParams& options) {
  for (const Box& box : previous) {
    if (box.id >= next_id) {
      throw Error("reconcile: next id " + std::to_string(next_id) + " is not above existing box id " +
                  std::to_string(box.id));
    }
  }
  const std::set<std::uint64_t> scope(in_scope.begin(), in_scope.end());
  Reconciled out;
  std::vector<const Box*> old_in_scope;
  std::vector<const Box*> kept;
  for (const Box& box : previous) (scope.count(box.id) ? old_in_scope : kept).push_back(&box);
  const std::vector<const Box*> candidates = candidates_of(resegmented, kept, options.redundant_tolerance);

  // Greedy matching: a matched old box keeps its id (and its geometry within the tolerance).
  std::vector<bool> new_used(candidates.size(), false);
  std::vector<bool> old_used(old_in_scope.size(), false);
  for (const auto& [n, o] : by_overlap(candidates, old_in_scope, options.min_overlap)) {
    if (new_used[n] || old_used[o]) continue;
    new_used[n] = old_used[o] = true;
    const Box& old_box = *old_in_scope[o];
    if (within_tolerance(*candidates[n], old_box, options)) {
      out.boxes.push_back(old_box);
    } else {
      Box updated = *candidates[n];
      updated.id = old_box.id;
      out.boxes.push_back(updated);
      out.modified.push_back(updated);
    }
  }
  for (const Box* box : kept) out.boxes.push_back(*box);
  for (std::size_t o = 0; o < old_in_scope.size(); ++o) {
    if (!old_used[o]) out.removed.push_back(old_in_scope[o]->id);
  }
  for (std::size_t n = 0; n < candidates.size(); ++n) {
    if (new_used[n]) continue;
    Box added = *candidates[n];
    added.id = next_id++;
    out.boxes.push_back(added);
    out.added.push_back(added);
  }
  out.next_id = next_id;
  sort_by_id(out);
  return out;
}

}  // namespace cellmap
