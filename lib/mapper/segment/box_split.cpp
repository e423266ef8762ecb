// SPDX-License-Identifier: Apache-2.0
#include "cellmap/segment/box_split.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <tuple>
#include <utility>

#include "cellmap/common/error.hpp"
#include "cellmap/common/parallel.hpp"
#include "cellmap/segment/free_space.hpp"

namespace cellmap {
namespace {

using Points = std::vector<Eigen::Vector3d>;

Points points_of(const Cloud& cloud, const std::vector<int>& indices) {
  Points points;
  points.reserve(indices.size());
  for (int i : indices) points.push_back(cloud[i].getVector3fMap().cast<double>());
  return points;
}

// The box with axes R spanning [low, high] in its own frame, grown to hold the points' cubes.
Box frame_box(const Eigen::Matrix3d& R, const Eigen::Vector3d& low, const Eigen::Vector3d& high,
              double cube) {
  Box box;
  box.center = R * (0.5 * (low + high));
  box.half_extents = (0.5 * (high - low)).array() + kBoxFitSlack;
  box.rotation = Eigen::Quaterniond(R).normalized();
  grow_to_hold_cubes(box, cube);
  return box;
}

// The volume frame_box(R, low, high, cube) has, worked out without building the box: the cubes' growth of
// the half extents depends on R alone.
class FrameBoxVolume {
 public:
  FrameBoxVolume(const Eigen::Matrix3d& R, double cube) {
    Box box;
    box.rotation = Eigen::Quaterniond(R).normalized();
    box.half_extents.setZero();
    grow_to_hold_cubes(box, cube);
    growth_ = box.half_extents;
  }
  [[nodiscard]] double operator()(const Eigen::Vector3d& low, const Eigen::Vector3d& high) const {
    Eigen::Vector3d half = (0.5 * (high - low)).array() + kBoxFitSlack;
    half += growth_;
    return 8.0 * half.prod();
  }

 private:
  Eigen::Vector3d growth_;
};

// One way to cut a part in two across an axis of its box: the first `at` points of `order` go one way.
struct Cut {
  std::vector<int> order;
  std::size_t at = 0;
  double volume = 0;  // of the two sides' boxes
};

// The box with axes R that holds the points and their cubes.
Box box_in_frame(const Points& points, const Eigen::Matrix3d& R, double cube) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (const Eigen::Vector3d& p : points) {
    low = low.cwiseMin(R.transpose() * p);
    high = high.cwiseMax(R.transpose() * p);
  }
  return frame_box(R, low, high, cube);
}

// The cut along `axis` of the points in `local` (their coordinates in the box frame R) that minimises the two
// sides' box volumes, each side keeping at least `min` points.
std::optional<Cut> best_cut(const Points& local, const std::vector<int>& indices, const Eigen::Matrix3d& R,
                            int axis, std::size_t min, double cube) {
  const std::size_t n = local.size();
  if (n < 2 * min || min < 1) return std::nullopt;
  std::vector<std::size_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return local[a][axis] < local[b][axis]; });
  std::vector<Eigen::Vector3d> low(n), high(n);  // extents of the first k + 1 points
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d& p = local[order[k]];
    low[k] = k ? low[k - 1].cwiseMin(p) : p;
    high[k] = k ? high[k - 1].cwiseMax(p) : p;
  }
  Eigen::Vector3d tail_low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
                  tail_high = -tail_low;
  Cut best;
  best.volume = std::numeric_limits<double>::infinity();
  const FrameBoxVolume box_volume(R, cube);
  for (std::size_t at = n; at-- > min;) {  // the points from `at` on form the other side
    tail_low = tail_low.cwiseMin(local[order[at]]);
    tail_high = tail_high.cwiseMax(local[order[at]]);
    if (n - at < min) continue;
    const double volume = box_volume(low[at - 1], high[at - 1]) + box_volume(tail_low, tail_high);
    if (volume < best.volume) best.at = at, best.volume = volume;
  }
  for (std::size_t k : order) best.order.push_back(indices[k]);
  return best;
}

// Per axis of `box`, and of the cloud's frame when the box is turned (scenes stand on floors and tables),
// the cuts that minimise the two sides' box volumes: one with any side size, one with sides of at least a
// tenth of the points (so one stray point does not hide every other cut). Smallest first.
std::vector<Cut> best_cuts(const Cloud& cloud, const std::vector<int>& indices, const Box& box, double cube) {
  std::vector<Eigen::Matrix3d> frames{box.rotation.toRotationMatrix()};
  if (!box.is_axis_aligned()) frames.push_back(Eigen::Matrix3d::Identity());
  std::vector<Cut> cuts;
  for (const Eigen::Matrix3d& R : frames) {
    Points local;
    local.reserve(indices.size());
    for (int i : indices) local.push_back(R.transpose() * cloud[i].getVector3fMap().cast<double>());
    for (int axis = 0; axis < 3; ++axis) {
      for (std::size_t min : {std::size_t{1}, indices.size() / 10}) {
        if (std::optional<Cut> cut = best_cut(local, indices, R, axis, min, cube))
          cuts.push_back(std::move(*cut));
      }
    }
  }
  std::sort(cuts.begin(), cuts.end(), [](const Cut& a, const Cut& b) { return a.volume < b.volume; });
  return cuts;
}

// The connected groups of `indices`: points linked through neighbours within the gap.
class Components {
 public:
  Components(const Neighbourhoods& nb, double gap)
      : nb_(nb), sq_gap_(static_cast<float>(gap * gap)), slot_(static_cast<std::size_t>(nb.size()), -1) {}

  // Flooded from each point not yet reached along its own neighbour links; a link to a point another flood
  // reached (the links are not symmetric) joins the two floods' labels. Groups in the order of their first
  // point in `indices`, each point in that order: what joining every linked pair would give, for a fraction
  // of the look-ups (a link mostly leads to a point of the flood at hand).
  std::vector<std::vector<int>> of(const std::vector<int>& indices) {
    for (std::size_t s = 0; s < indices.size(); ++s) slot_[indices[s]] = static_cast<int>(s);
    std::vector<int> flood(indices.size(), -1), joined;  // joined: per flood, the flood it joined
    const auto find = [&](int x) {
      while (joined[x] != x) x = joined[x] = joined[joined[x]];
      return x;
    };
    std::vector<int> stack;
    for (std::size_t seed = 0; seed < indices.size(); ++seed) {
      if (flood[seed] >= 0) continue;
      const int label = static_cast<int>(joined.size());
      joined.push_back(label);
      flood[seed] = label;
      stack.assign(1, static_cast<int>(seed));
      while (!stack.empty()) {
        const int s = stack.back();
        stack.pop_back();
        for (int j = 0; j < nb_.k; ++j) {
          const int other = nb_.neighbour(indices[s], j);
          if (other < 0 || nb_.sq_distance(indices[s], j) > sq_gap_) break;
          const int t = slot_[other];
          if (t < 0) continue;
          if (flood[t] < 0) {
            flood[t] = label;
            stack.push_back(t);
          } else if (flood[t] != label) {
            joined[find(flood[t])] = find(label);
          }
        }
      }
    }
    std::vector<std::vector<int>> groups;
    std::vector<int> group_of(joined.size(), -1);
    for (std::size_t s = 0; s < indices.size(); ++s) {
      int& g = group_of[find(flood[s])];
      if (g < 0) g = static_cast<int>(groups.size()), groups.emplace_back();
      groups[g].push_back(indices[s]);
    }
    for (int i : indices) slot_[i] = -1;
    return groups;
  }

 private:
  const Neighbourhoods& nb_;
  float sq_gap_;
  std::vector<int> slot_;  // position of a point in the indices being grouped, -1 = not among them
};

// Splits segments, one at a time (its scratch space is its own: one per thread).
class Splitter {
 public:
  Splitter(const Cloud& cloud, const Neighbourhoods& nb, const BoxSplitParams& params)
      : cloud_(cloud), params_(params), components_(nb, params.gap) {}

  // Appends `indices` to `out` as one segment, or the segments of its pieces. Returns whether it was split.
  bool split(const std::vector<int>& indices, const SeenFreeSpace& space, int depth,
             std::vector<std::vector<int>>& out) {
    if (depth < params_.max_depth && indices.size() >= 2) {
      const Box box = fit_box(cloud_, indices, params_.kind, params_.cube);
      const double needed = params_.min_gain * box.volume();
      const double free = space.free_volume(box);
      // Pieces can at most free what the box blocks: skip the search when that is too little.
      if (free >= needed) {
        const auto frees_enough = [&](const std::vector<std::vector<int>>& pieces) {
          double left = 0;
          for (const std::vector<int>& piece : pieces) left += space.free_volume(piece_box(piece, box));
          return free - left >= needed;
        };
        if (std::optional<std::vector<std::vector<int>>> pieces =
                first_division(indices, box, frees_enough)) {
          for (const std::vector<int>& piece : *pieces) split(piece, space, depth + 1, out);
          return true;
        }
      }
    }
    out.push_back(indices);
    return false;
  }

 private:
  // A quick box of a piece: the smaller of its boxes along the part's axes and along the cloud's.
  [[nodiscard]] Box piece_box(const std::vector<int>& piece, const Box& part) const {
    const Points points = points_of(cloud_, piece);
    const Box along_part = box_in_frame(points, part.rotation.toRotationMatrix(), params_.cube);
    const Box along_cloud = box_in_frame(points, Eigen::Matrix3d::Identity(), params_.cube);
    return along_cloud.volume() < along_part.volume() ? along_cloud : along_part;
  }

  // The first way to divide a part that `accept`s, of these in order: its connected pieces (when it has
  // several), then each cut with the connected pieces of both sides. Each is grouped only once the ones
  // before it were refused: grouping is most of a split's cost, and the first division usually passes.
  template <class Accept>
  std::optional<std::vector<std::vector<int>>> first_division(const std::vector<int>& indices, const Box& box,
                                                              const Accept& accept) {
    std::vector<std::vector<int>> whole = components_.of(indices);
    if (whole.size() > 1 && accept(whole)) return whole;
    for (const Cut& cut : best_cuts(cloud_, indices, box, params_.cube)) {
      const auto middle = cut.order.begin() + static_cast<std::ptrdiff_t>(cut.at);
      std::vector<std::vector<int>> pieces = components_.of({cut.order.begin(), middle});
      for (std::vector<int>& piece : components_.of({middle, cut.order.end()}))
        pieces.push_back(std::move(piece));
      if (accept(pieces)) return pieces;
    }
    return std::nullopt;
  }

  const Cloud& cloud_;
  const BoxSplitParams& params_;
  Components components_;
};

// The cell-frame bounds of two boxes come within `gap` of each other on every axis.
bool near(const Box& a, const Box& b, double gap) {
  const Eigen::Vector3d reach = a.rotation.toRotationMatrix().cwiseAbs() * a.half_extents +
                                b.rotation.toRotationMatrix().cwiseAbs() * b.half_extents;
  return ((a.center - b.center).cwiseAbs() - reach).maxCoeff() <= gap;
}

struct Part {
  std::vector<int> members;
  Points hull;  // the members' hull vertices: the box of the union of parts is the box of their hulls
  Box box;
  std::vector<std::shared_ptr<const SeenFreeSpace>> views;  // together: what the members hide
  bool live = true;
};

constexpr std::size_t kMaxViews = 4;  // a part seen through more views gets one view of all its points

class Joiner {
 public:
  Joiner(const Cloud& cloud, const Eigen::Vector3d& viewpoint, const BoxSplitParams& params)
      : cloud_(cloud), viewpoint_(viewpoint), params_(params) {}

  void add(std::vector<int> members) {
    Part part;
    part.hull = hull_vertices(points_of(cloud_, members));
    part.box = fit_box(part.hull, params_.kind, params_.cube);
    part.members = std::move(members);
    part.views.push_back(view_of(part.members));
    parts_.push_back(std::move(part));
  }

  // Joins the cheapest pair while one is cheap enough; returns the number of joins.
  std::size_t run() {
    std::vector<std::pair<std::size_t, std::size_t>> candidates;
    for (std::size_t a = 0; a < parts_.size(); ++a) {
      for (std::size_t b = a + 1; b < parts_.size(); ++b) candidates.emplace_back(a, b);
    }
    consider(candidates);
    std::size_t joins = 0;
    while (!pairs_.empty()) {
      const auto cheapest = std::min_element(pairs_.begin(), pairs_.end());
      // Plain variables, not a structured binding: C++17 lambdas cannot capture bindings (clang refuses).
      const std::size_t a = std::get<1>(*cheapest);
      const std::size_t b = std::get<2>(*cheapest);
      join(a, b);
      ++joins;
      pairs_.erase(std::remove_if(pairs_.begin(), pairs_.end(),
                                  [&](const auto& p) {
                                    return std::get<1>(p) == a || std::get<2>(p) == a ||
                                           std::get<1>(p) == b || std::get<2>(p) == b;
                                  }),
                   pairs_.end());
      candidates.clear();
      for (std::size_t c = 0; c < parts_.size(); ++c) {
        if (c != a && parts_[c].live) candidates.emplace_back(std::min(a, c), std::max(a, c));
      }
      consider(candidates);
    }
    return joins;
  }

  [[nodiscard]] Segments labels(std::size_t size) const {
    std::vector<int> label(size, -1);
    int count = 0;
    for (const Part& part : parts_) {
      if (!part.live) continue;
      for (int i : part.members) label[i] = count;
      ++count;
    }
    return compact_segments(label);
  }

 private:
  // Records the pairs of parts that are cheap enough to join, in the order given. Each pair's cost is judged
  // on its own, so they are spread over the threads (pair i on thread i mod threads: near pairs, which cost
  // the free-space judgements, lie anywhere in the list).
  void consider(const std::vector<std::pair<std::size_t, std::size_t>>& candidates) {
    std::vector<double> cost(candidates.size());
    const int threads = std::clamp(params_.threads, 1, std::max(1, static_cast<int>(candidates.size())));
    parallel_for(threads, threads, [&](int t) {
      for (std::size_t i = std::size_t(t); i < candidates.size(); i += std::size_t(threads))
        cost[i] = join_cost(parts_[candidates[i].first], parts_[candidates[i].second]);
    });
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (cost[i] <= params_.max_growth)
        pairs_.emplace_back(cost[i], candidates[i].first, candidates[i].second);
    }
  }

  // The free space the box of two parts' union blocks beyond their own boxes, as a share of its volume;
  // infinite for parts too far apart to be joined.
  [[nodiscard]] double join_cost(const Part& x, const Part& y) const {
    if (!near(x.box, y.box, params_.adjacency)) return std::numeric_limits<double>::infinity();
    const Box joined = quick_union(x, y);
    std::vector<const SeenFreeSpace*> views;
    for (const auto& v : x.views) views.push_back(v.get());
    for (const auto& v : y.views) views.push_back(v.get());
    const double added = free_volume(joined, views) - free_volume(x.box, views) - free_volume(y.box, views);
    return added / joined.volume();
  }

  // The smaller of the two boxes that keep one part's axes and hold both parts: a cheap stand-in for the
  // union's own fit (never smaller than it), used to judge a join.
  [[nodiscard]] Box quick_union(const Part& x, const Part& y) const {
    Points both = x.hull;
    both.insert(both.end(), y.hull.begin(), y.hull.end());
    const Box along_x = box_in_frame(both, x.box.rotation.toRotationMatrix(), params_.cube);
    const Box along_y = box_in_frame(both, y.box.rotation.toRotationMatrix(), params_.cube);
    return along_x.volume() < along_y.volume() ? along_x : along_y;
  }

  void join(std::size_t a, std::size_t b) {
    Part &x = parts_[a], &y = parts_[b];
    x.members.insert(x.members.end(), y.members.begin(), y.members.end());
    x.hull.insert(x.hull.end(), y.hull.begin(), y.hull.end());
    x.hull = hull_vertices(x.hull);
    x.box = fit_box(x.hull, params_.kind, params_.cube);
    x.views.insert(x.views.end(), y.views.begin(), y.views.end());
    if (x.views.size() > kMaxViews) x.views = {view_of(x.members)};
    y.live = false;
    y.members.clear();
    y.hull.clear();
    y.views.clear();
  }

  [[nodiscard]] std::shared_ptr<const SeenFreeSpace> view_of(const std::vector<int>& members) const {
    return std::make_shared<const SeenFreeSpace>(cloud_, members, viewpoint_, params_.angular_step,
                                                 params_.margin);
  }

  const Cloud& cloud_;
  Eigen::Vector3d viewpoint_;
  const BoxSplitParams& params_;
  std::vector<Part> parts_;
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs_;
};

}  // namespace

void BoxSplitParams::validate() const {
  if (!(min_gain > 0 && min_gain <= 1)) throw Error("box split: min_gain must be in (0, 1]");
  if (!(max_growth >= 0 && max_growth < 1)) throw Error("box split: max_growth must be in [0, 1)");
  if (max_depth < 0) throw Error("box split: max_depth must be >= 0");
  if (threads < 1) throw Error("box split: threads must be >= 1");
  if (!(angular_step > 0) || !(gap > 0) || !(margin >= 0) || !(adjacency >= 0) || !(cube >= 0)) {
    throw Error("box split: angular_step and gap must be > 0; margin, adjacency and cube >= 0");
  }
}

Segments split_by_free_space(const Cloud& cloud, const Neighbourhoods& neighbourhoods,
                             const Segments& segments, const Eigen::Vector3d& viewpoint,
                             const BoxSplitParams& params, std::size_t* split_count) {
  params.validate();
  if (segments.label.size() != cloud.size() ||
      static_cast<std::size_t>(neighbourhoods.size()) != cloud.size()) {
    throw Error("split: cloud, neighbourhoods and labels differ in size");
  }
  // Segments are split independently, thread t taking segments t, t + threads, …; their pieces are labelled
  // in segment order afterwards, so the labels do not depend on the threads.
  const std::vector<std::vector<int>> members = segments.members();
  std::vector<std::vector<std::vector<int>>> pieces(members.size());
  std::vector<char> was_split(members.size(), 0);
  const int threads = std::clamp(params.threads, 1, std::max(1, static_cast<int>(members.size())));
  parallel_for(threads, threads, [&](int t) {
    Splitter splitter(cloud, neighbourhoods, params);
    for (std::size_t m = std::size_t(t); m < members.size(); m += std::size_t(threads)) {
      if (members[m].empty()) continue;
      const SeenFreeSpace space(cloud, members[m], viewpoint, params.angular_step, params.margin);
      was_split[m] = splitter.split(members[m], space, 0, pieces[m]);
    }
  });
  Segments out;
  out.label.assign(cloud.size(), -1);
  for (const std::vector<std::vector<int>>& of_segment : pieces) {
    for (const std::vector<int>& piece : of_segment) {
      for (int i : piece) out.label[i] = out.count;
      ++out.count;
    }
  }
  if (split_count) *split_count = static_cast<std::size_t>(std::count(was_split.begin(), was_split.end(), 1));
  return out;
}

Segments join_by_free_space(const Cloud& cloud, const Segments& segments, const Eigen::Vector3d& viewpoint,
                            const BoxSplitParams& params, std::size_t* join_count) {
  params.validate();
  if (segments.label.size() != cloud.size()) throw Error("join: labels and cloud differ in size");
  Joiner joiner(cloud, viewpoint, params);
  for (std::vector<int>& members : segments.members()) {
    if (!members.empty()) joiner.add(std::move(members));
  }
  const std::size_t joins = params.max_growth > 0 ? joiner.run() : 0;
  if (join_count) *join_count = joins;
  return joiner.labels(cloud.size());
}

}  // namespace cellmap
