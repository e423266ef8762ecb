// SPDX-License-Identifier: Apache-2.0
#include "cellmap/common/text.hpp"

#include <gtest/gtest.h>

#include "support/test_support.hpp"

namespace cellmap {
namespace {

using test::error_of;

TEST(TextTest, SplitTrimsAndKeepsEmptyItems) {
  EXPECT_EQ(split(" a, b ,,c,", ','), (std::vector<std::string>{"a", "b", "", "c", ""}));
  EXPECT_TRUE(split("", ',').empty());
  EXPECT_EQ(trim(" \t x y\r"), "x y");
}

TEST(TextTest, LowerExtensionKeepsTheDotOfTheLastExtensionOnly) {
  EXPECT_EQ(lower_extension("frames/Depth_0001.PNG"), ".png");
  EXPECT_EQ(lower_extension("cloud.tar.PCD"), ".pcd");
  EXPECT_EQ(lower_extension("dir.d/poses"), "");
  EXPECT_EQ(lower_extension(""), "");
}

TEST(TextTest, ParseFiniteTakesWholeFiniteNumbersOnly) {
  EXPECT_DOUBLE_EQ(parse_finite("-2.5e-3", "x"), -2.5e-3);
  EXPECT_EQ(error_of([] { (void)parse_finite("2.5m", "poses.csv:3: x"); }),
            "poses.csv:3: x: '2.5m' is not a finite number");
  EXPECT_EQ(error_of([] { (void)parse_finite("inf", "x"); }), "x: 'inf' is not a finite number");
  EXPECT_EQ(error_of([] { (void)parse_finite("", "x"); }), "x: '' is not a finite number");
}

}  // namespace
}  // namespace cellmap
