// SPDX-License-Identifier: Apache-2.0
#pragma once
// The result every segmentation step exchanges: one segment label per point.

#include <vector>

namespace cellmap {

/// A partition of (some of) a cloud's points into segments 0..count-1; label -1 = in no segment.
/// Indices refer to the cloud the step was given. Plain value type.
struct Segments final {
  std::vector<int> label;
  int count = 0;

  /// The point indices of each segment, ascending.
  [[nodiscard]] std::vector<std::vector<int>> members() const {
    std::vector<std::vector<int>> result(static_cast<std::size_t>(count));
    for (std::size_t i = 0; i < label.size(); ++i) {
      if (label[i] >= 0) result[static_cast<std::size_t>(label[i])].push_back(static_cast<int>(i));
    }
    return result;
  }
  /// How many points are in no segment.
  [[nodiscard]] std::size_t unlabelled() const {
    std::size_t n = 0;
    for (int l : label) n += l < 0;
    return n;
  }
};

/// Renumbers labels to 0..count-1 in order of first appearance, turning segments listed in `drop` (by their
/// old label, true = drop) into -1.
[[nodiscard]] Segments compact_segments(const std::vector<int>& label, const std::vector<bool>& drop = {});

}  // namespace cellmap
