// SPDX-License-Identifier: Apache-2.0
#pragma once
// A deterministic sequence of environments for transport tests: each version changes exactly one box
// (every third version adds one, the others move one); no version removes a box, so a subscriber that
// ever sees a removal has been misled (e.g. by a restarting publisher).

#include "cellmap/environment/environment.hpp"

namespace cellmap::test {

inline Box test_box(std::uint64_t id, double x) {
  Box box;
  box.id = id;
  box.center = {x, 0.25 * static_cast<double>(id % 4), 0.5};
  box.half_extents = {0.1, 0.2, 0.3};
  box.points = 50 + id;
  return box;
}

/// The environment of version `version`, made from `previous` by one change.
inline Environment next_environment(const Environment& previous, std::uint64_t version,
                                    std::int64_t stamp_ns) {
  std::vector<Box> boxes = previous.boxes();
  if (boxes.empty() || version % 3 == 0) {
    boxes.push_back(test_box(version, 0.1 * static_cast<double>(boxes.size())));
  } else {
    Box& moved = boxes[version % boxes.size()];
    moved.center.z() += 0.01;
  }
  return Environment(previous.cell(), version, stamp_ns, std::move(boxes));
}

}  // namespace cellmap::test
