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

TEST(LogBudgetTest, AFloodOfAcceptedInputsLogsAFewLinesASecondAndSaysHowManyMore) {
  LogBudget budget(3, 1s);
  const LogBudget::Clock::time_point start{};
  std::vector<std::string> lines;
  for (int i = 0; i < 100; ++i) {
    if (auto line = budget.admit("edit " + std::to_string(i), start + 5ms * i)) lines.push_back(*line);
  }
  EXPECT_EQ(lines, (std::vector<std::string>{"edit 0", "edit 1", "edit 2"}));
  EXPECT_EQ(budget.admit("edit 100", start + 1s).value_or("(held back)"), "edit 100 (97 more not logged)");
  EXPECT_EQ(budget.admit("edit 101", start + 1s).value_or("(held back)"), "edit 101");
}

}  // namespace
}  // namespace cellmap::daemon
