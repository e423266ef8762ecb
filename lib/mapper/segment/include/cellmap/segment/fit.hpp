#pragma once
// Fitting a box around a set of points.

#include <Eigen/Core>

#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/frame/cloud.hpp"

namespace cellmap {

/// Axis-aligned (rotation identity) or oriented along the principal axes of the points.
enum class BoxKind { kAxisAligned, kOriented };

/// "aabb" / "obb". @throws Error naming `what` for any other text.
[[nodiscard]] BoxKind box_kind_from_string(const std::string& text, const std::string& what = "box kind");
[[nodiscard]] const char* to_string(BoxKind kind);

/// Half extents are grown by this much (metres) so that the extreme points stay inside under the rounding of
/// a containment test in the caller's own arithmetic (coverage is a safety property).
inline constexpr double kBoxFitSlack = 1e-6;

/// The smallest box of the requested kind, in the points' frame, that contains every point
/// `cloud[indices[i]]`, with `points` = indices.size() and id 0.
/// Oriented: the axes are the eigenvectors of the points' covariance (Eigen SelfAdjointEigenSolver;
/// right-handed, so the rotation is proper) and the extents come from the points projected on them. PCA boxes
/// are not always smaller than the axis-aligned one (e.g. a cube seen as three faces); then the axis-aligned
/// box is returned, so an oriented box never has a larger volume than the axis-aligned box of the same
/// points. Cost: two passes over the points. @throws Error if `indices` is empty or an index is out of range.
[[nodiscard]] Box fit_box(const Cloud& cloud, const std::vector<int>& indices, BoxKind kind);

}  // namespace cellmap
