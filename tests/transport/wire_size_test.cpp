// SPDX-License-Identifier: Apache-2.0
#include "wire_size.hpp"

#include <gtest/gtest.h>

namespace cellmap::transport {
namespace {

TEST(WireSizeTest, MatchesTheXcdr1Layout) {
  // Header 4; cell "c": length 4 + "c\0" 2, padded to 8; version 8; stamp 8; box count 4.
  const Environment empty("c", 1, 0, {});
  EXPECT_EQ(wire_size(empty), 4u + 28u);
  // A box: id 8, center 24, half extents 24, rotation 32, points 8, space 1 = 97 bytes, 8-aligned (4
  // padding before the first, 7 between boxes).
  std::vector<Box> boxes(200);
  for (std::size_t i = 0; i < boxes.size(); ++i) boxes[i].id = i + 1;
  EXPECT_EQ(wire_size(Environment("c", 1, 0, boxes)), 4u + 32u + 199u * 104u + 97u);
  // Delta: cell 8, from 8, to 8, stamp 8, added count 4 + pad 4, one box 97, pad 3, modified count 4, removed
  // count 4.
  EnvironmentDelta delta;
  delta.cell = "c";
  delta.added = {boxes[0]};
  EXPECT_EQ(wire_size(delta), 4u + 32u + 8u + 97u + 3u + 4u + 4u);
}

}  // namespace
}  // namespace cellmap::transport
