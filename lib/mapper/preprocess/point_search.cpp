// SPDX-License-Identifier: Apache-2.0
#include "cellmap/preprocess/point_search.hpp"

// FLANN's templates instantiated here stay ours: exported, they would replace the copies PCL's libraries
// call (the dynamic linker binds those to the executable's), and a PCL anchor would run our build of them.
#pragma GCC visibility push(hidden)
#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/result_set.h>
#pragma GCC visibility pop

#include <algorithm>
#include <cmath>

#include "cellmap/common/error.hpp"

namespace cellmap {

struct __attribute__((visibility("hidden"))) PointSearch::Tree {
  using Index = flann::KDTreeSingleIndex<flann::L2_Simple<float>>;

  Tree(const Cloud& cloud, const std::vector<int>* subset) {
    const std::size_t n = subset ? subset->size() : cloud.size();
    coordinates.reserve(3 * n);
    original.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const int at = subset ? (*subset)[i] : static_cast<int>(i);
      const pcl::PointXYZ& p = cloud.at(static_cast<std::size_t>(at));
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw Error("point search: the cloud has a non-finite point (drop them when loading)");
      coordinates.insert(coordinates.end(), {p.x, p.y, p.z});
      original.push_back(at);
    }
    if (n == 0) return;
    index = std::make_unique<Index>(flann::Matrix<float>(coordinates.data(), n, 3),
                                    flann::KDTreeSingleIndexParams(15));
    index->buildIndex();
  }

  // Searches `found` (a FLANN result set) and returns its first `count` (all if 0) as indices into the cloud
  // and squared distances, in the tree's order or nearest first.
  template <typename Found>
  int search(Found found, const pcl::PointXYZ& query, std::size_t count, bool sorted, pcl::Indices& indices,
             std::vector<float>& sq_distances) const {
    const float point[3] = {query.x, query.y, query.z};
    index->findNeighbors(found, point, flann::SearchParams(-1, 0.0f, sorted));  // exact, as PCL's
    count = count ? std::min(count, found.size()) : found.size();
    thread_local std::vector<std::size_t> at;  // FLANN's indices, one allocation per thread
    at.resize(count);
    sq_distances.resize(count);
    if (count > 0) found.copy(at.data(), sq_distances.data(), count, sorted);
    indices.resize(count);
    for (std::size_t i = 0; i < count; ++i) indices[i] = original[at[i]];
    return static_cast<int>(count);
  }

  std::vector<float> coordinates;  // x, y, z of each indexed point
  std::vector<int> original;       // the cloud index of each indexed point
  std::unique_ptr<Index> index;
};

PointSearch::PointSearch(const Cloud& cloud) : tree_(std::make_unique<Tree>(cloud, nullptr)) {}

PointSearch::PointSearch(const Cloud& cloud, const std::vector<int>& subset)
    : tree_(std::make_unique<Tree>(cloud, &subset)) {}

PointSearch::~PointSearch() = default;
PointSearch::PointSearch(PointSearch&&) noexcept = default;
PointSearch& PointSearch::operator=(PointSearch&&) noexcept = default;

int PointSearch::size() const {
  return static_cast<int>(tree_->original.size());
}

int PointSearch::nearest(const pcl::PointXYZ& query, int k, pcl::Indices& indices,
                         std::vector<float>& sq_distances) const {
  const std::size_t wanted = static_cast<std::size_t>(std::clamp(k, 0, size()));
  if (wanted == 0) {
    indices.clear();
    sq_distances.clear();
    return 0;
  }
  // FLANN's own choice for k-NN: a heap above 250 neighbours, a sorted array below.
  if (wanted > KNN_HEAP_THRESHOLD)
    return tree_->search(flann::KNNResultSet2<float>(wanted), query, wanted, true, indices, sq_distances);
  return tree_->search(flann::KNNSimpleResultSet<float>(wanted), query, wanted, true, indices, sq_distances);
}

int PointSearch::within(const pcl::PointXYZ& query, double radius, bool sorted, pcl::Indices& indices,
                        std::vector<float>& sq_distances) const {
  if (size() == 0) {
    indices.clear();
    sq_distances.clear();
    return 0;
  }
  const flann::RadiusResultSet<float> found(static_cast<float>(radius * radius));
  return tree_->search(found, query, 0, sorted, indices, sq_distances);
}

}  // namespace cellmap
