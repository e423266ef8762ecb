// SPDX-License-Identifier: Apache-2.0
// cellmapd's refused DDS inputs: every one counted, at most one log line a second.
#include "input_refusals.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace cellmap::daemon {
namespace {

using namespace std::chrono_literals;

TEST(InputRefusalsTest, CountsEveryRefusalAndLogsAtMostOnceASecond) {
  std::vector<std::string> lines;
  InputRefusals refusals([&](const std::string& line) { lines.push_back(line); });
  const InputRefusals::Clock::time_point start{};
  refusals.refuse("first", start);
  for (int i = 0; i < 100; ++i) refusals.refuse("flood", start + 10ms * i);  // within 1 s of the first
  EXPECT_EQ(refusals.count(), 101u);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "refused: first (1 inputs refused so far)");
  refusals.refuse("later", start + 1s);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[1], "refused: later (102 inputs refused so far)");
  refusals.refuse("too soon", start + 1500ms);
  EXPECT_EQ(lines.size(), 2u);
  EXPECT_EQ(refusals.count(), 103u);
}

}  // namespace
}  // namespace cellmap::daemon
