// SPDX-License-Identifier: Apache-2.0
#include "cellmap/preprocess/neighbourhoods.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

#include "cellmap/common/error.hpp"
#include "cellmap/common/parallel.hpp"
#include "cellmap/preprocess/point_search.hpp"

namespace cellmap {

namespace {

// Fewer points per thread than this are searched faster on one thread than the others take to start.
constexpr int kMinPointsPerThread = 256;

void require_finite(const Cloud& cloud) {
  for (const pcl::PointXYZ& p : cloud) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      throw Error("neighbourhoods: the cloud has a non-finite point (drop them when loading)");
    }
  }
}

// Eq. 2: the normal (facing `viewpoint`) and curvature of point i from the covariance of its neighbourhood
// `found[0, count)` about the neighbourhood mean, accumulated relative to the query point so that
// coordinates of a few metres do not cancel in float.
void fit_normal(const Cloud& cloud, int i, const pcl::Indices& found, int count,
                const Eigen::Vector3f& viewpoint, Neighbourhoods& result) {
  const Eigen::Vector3d origin = cloud[i].getVector3fMap().cast<double>();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int j = 0; j < count; ++j) {
    const Eigen::Vector3d d = cloud[found[j]].getVector3fMap().cast<double>() - origin;
    mean += d;
    scatter.noalias() += d * d.transpose();
  }
  mean /= count;
  const Eigen::Matrix3d covariance = scatter / count - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  const Eigen::Vector3d lambda = solver.eigenvalues().cwiseMax(0.0);  // ascending
  const double total = lambda.sum();
  Eigen::Vector3f normal = solver.eigenvectors().col(0).cast<float>();
  if (normal.dot(viewpoint - cloud[i].getVector3fMap()) < 0.0f) normal = -normal;
  result.normals[i] = normal;
  result.curvature[i] = total > 0.0 ? static_cast<float>(lambda[0] / total) : 0.0f;
}

}  // namespace

Neighbourhoods compute_neighbourhoods(const Cloud& cloud, int k, bool with_normals,
                                      const Eigen::Vector3f& viewpoint, int threads) {
  if (k < 1) throw Error("neighbourhoods: k must be >= 1, got " + std::to_string(k));
  require_finite(cloud);
  const int n = static_cast<int>(cloud.size());
  Neighbourhoods result;
  result.k = k;
  result.indices.assign(static_cast<std::size_t>(n) * k, -1);
  result.sq_distances.assign(static_cast<std::size_t>(n) * k, 0.0f);
  result.mean_distance.assign(n, 0.0f);
  if (with_normals) {
    result.normals.assign(n, Eigen::Vector3f::UnitZ());
    result.curvature.assign(n, 0.0f);
  }
  if (n == 0) return result;

  const PointSearch tree(cloud);
  const int searched = k + 1;  // the query point is its own nearest neighbour
  // Each thread a contiguous run of points: a search leaves only that point's entries of `result`.
  const int chunks = std::clamp(threads, 1, std::max(1, n / kMinPointsPerThread));
  parallel_for(chunks, chunks, [&](int chunk) {
    pcl::Indices found(searched);
    std::vector<float> found_sq(searched);
    const int end = static_cast<int>(static_cast<long>(n) * (chunk + 1) / chunks);
    for (int i = static_cast<int>(static_cast<long>(n) * chunk / chunks); i < end; ++i) {
      const int count = tree.nearest(cloud[i], searched, found, found_sq);
      // found[0] is the query point (or a duplicate of it at distance 0).
      double sum = 0.0;
      for (int j = 1; j < count; ++j) {
        result.indices[static_cast<std::size_t>(i) * k + j - 1] = found[j];
        result.sq_distances[static_cast<std::size_t>(i) * k + j - 1] = found_sq[j];
        sum += std::sqrt(static_cast<double>(found_sq[j]));  // in double, as PCL does
      }
      result.mean_distance[i] = static_cast<float>(sum / k);
      if (with_normals && count >= 3) fit_normal(cloud, i, found, count, viewpoint, result);
    }
  });
  return result;
}

Neighbourhoods subset_neighbourhoods(const Neighbourhoods& all, const std::vector<int>& kept) {
  std::vector<int> renumber(static_cast<std::size_t>(all.size()), -1);
  for (std::size_t n = 0; n < kept.size(); ++n) {
    if (kept[n] < 0 || kept[n] >= all.size() || (n > 0 && kept[n] <= kept[n - 1])) {
      throw Error("subset_neighbourhoods: kept indices must be ascending and in range");
    }
    renumber[kept[n]] = static_cast<int>(n);
  }
  const bool with_normals = !all.normals.empty();
  Neighbourhoods result;
  result.k = all.k;
  result.indices.assign(kept.size() * all.k, -1);
  result.sq_distances.assign(kept.size() * all.k, 0.0f);
  result.mean_distance.resize(kept.size());
  if (with_normals) {
    result.normals.resize(kept.size());
    result.curvature.resize(kept.size());
  }
  for (std::size_t n = 0; n < kept.size(); ++n) {
    const int i = kept[n];
    std::size_t out = n * all.k;
    for (int j = 0; j < all.k; ++j) {
      const int other = all.neighbour(i, j);
      if (other < 0) break;
      if (renumber[other] < 0) continue;
      result.indices[out] = renumber[other];
      result.sq_distances[out] = all.sq_distance(i, j);
      ++out;
    }
    result.mean_distance[n] = all.mean_distance[i];
    if (with_normals) {
      result.normals[n] = all.normals[i];
      result.curvature[n] = all.curvature[i];
    }
  }
  return result;
}

}  // namespace cellmap
