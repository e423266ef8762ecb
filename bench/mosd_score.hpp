// SPDX-License-Identifier: Apache-2.0
#pragma once
// Scoring boxes against the per-point object labels of the mOSD scenes (shared by the data test and the
// mosd_table program, so both report the same figures).
//
// Objects: points with label >= 20; object id = label / 10 (several labels of one object are disjoint parts).
// Volumetric IoU of one object (reported first): the exact volume IoU (boxes/volume.hpp) of its tight box,
// the minimum-volume oriented box of its points, with the box that matches it best; unlike the point-set IoU
// it sees the free space a box swallows beyond the object. Coverage: share of all labelled object points of
// the file that lie inside some box (geometric containment, which is what a planner sees; points dropped by
// the pipeline count as covered only if a box holds them). IoU of one object: point-set IoU |O ∩ B| / |O ∪ B|
// of its points O with the points B of the file that lie inside a box, maximised over the boxes. It is 1 when
// one box holds exactly that object's points, and drops when the object is split over several boxes or its
// box also swallows table or other objects' points.

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "cellmap/boxes/box.hpp"
#include "cellmap/boxes/volume.hpp"
#include "cellmap/frame/cloud.hpp"
#include "cellmap/segment/fit.hpp"

namespace cellmap::mosd {

struct Score {
  std::size_t object_points = 0;
  std::size_t covered_object_points = 0;
  std::vector<double> volume_iou;   ///< one per object, ascending object id
  std::vector<double> iou;          ///< point-set IoU, one per object, ascending object id
  std::vector<std::string> detail;  ///< per object: "id size | best box: held, object points in it"
  [[nodiscard]] double coverage() const {
    return object_points == 0 ? 1.0 : static_cast<double>(covered_object_points) / object_points;
  }
};

inline int object_of(std::uint32_t label) {
  return label >= 20 ? static_cast<int>(label / 10) : -1;
}

inline Score score(const Cloud& points, const std::vector<std::uint32_t>& labels,
                   const std::vector<Box>& boxes) {
  Score s;
  std::map<int, std::size_t> object_size;
  std::map<int, std::vector<Eigen::Vector3d>> object_points;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const int object = object_of(labels[i]);
    if (object < 0) continue;
    ++object_size[object];
    object_points[object].push_back(points[i].getVector3fMap().cast<double>());
  }
  std::vector<bool> covered(points.size(), false);
  // Per box: how many points it holds, and how many of each object.
  std::vector<std::size_t> box_size(boxes.size(), 0);
  std::vector<std::map<int, std::size_t>> box_object(boxes.size());
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!boxes[b].contains(points[i].getVector3fMap().cast<double>())) continue;
      covered[i] = true;
      ++box_size[b];
      if (object_of(labels[i]) >= 0) ++box_object[b][object_of(labels[i])];
    }
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (object_of(labels[i]) < 0) continue;
    ++s.object_points;
    s.covered_object_points += covered[i];
  }
  for (const auto& [object, size] : object_size) {
    const Box tight = fit_box(object_points[object], BoxKind::kOriented);
    double best_volume = 0.0;
    for (const Box& box : boxes) best_volume = std::max(best_volume, volume_iou(tight, box));
    s.volume_iou.push_back(best_volume);
    double best = 0.0;
    std::size_t best_box = boxes.size();
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      const auto it = box_object[b].find(object);
      if (it == box_object[b].end()) continue;
      const double inter = static_cast<double>(it->second);
      const double iou = inter / (static_cast<double>(size) + box_size[b] - inter);
      if (iou > best) {
        best = iou;
        best_box = b;
      }
    }
    s.iou.push_back(best);
    std::string text = "object " + std::to_string(object) + ": " + std::to_string(size) +
                       " points, volumetric IoU " + std::to_string(best_volume) + ", point-set IoU " +
                       std::to_string(best);
    if (best_box < boxes.size()) {
      text += ", best box " + std::to_string(boxes[best_box].id) + " holds " +
              std::to_string(box_size[best_box]) + " points (" +
              std::to_string(box_object[best_box][object]) + " of this object); boxes holding it:";
      for (std::size_t b = 0; b < boxes.size(); ++b) {
        const auto it = box_object[b].find(object);
        if (it != box_object[b].end())
          text += " " + std::to_string(boxes[b].id) + ":" + std::to_string(it->second);
      }
    }
    s.detail.push_back(text);
  }
  return s;
}

inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace cellmap::mosd
