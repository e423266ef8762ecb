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

TEST(TextTest, SingleLineKeepsValidTextAndReplacesWhatBreaksALineOrAPage) {
  EXPECT_EQ(single_line("cell-1 Zelle \u00e4 \u4e2d \U0001F916"), "cell-1 Zelle \u00e4 \u4e2d \U0001F916");
  EXPECT_EQ(single_line("a\nb\tc\x7f\r"), "a?b?c??");
  EXPECT_EQ(single_line("c\xffx"), "c?x");                        // not UTF-8
  EXPECT_EQ(single_line("\xc0\xafx"), "??x");                     // an overlong '/'
  EXPECT_EQ(single_line("\xed\xa0\x80"), "???");                  // a surrogate
  EXPECT_EQ(single_line("\xf4\x90\x80\x80"), "????");             // past U+10FFFF
  EXPECT_EQ(single_line("ab\xe4\xb8"), "ab??");                   // cut inside a character
  EXPECT_EQ(single_line("\xc2\x85x"), "?x");                      // C1 next line
  EXPECT_EQ(single_line("a\u2028b\u2029c"), "a?b?c");             // line and paragraph separators
  EXPECT_EQ(single_line("x\u202eevil\u2066\u200f"), "x?evil??");  // bidirectional controls
  EXPECT_EQ(single_line(std::string("a\0b", 3)), "a?b");
}

TEST(TextTest, SingleLineCutsAtMaxBytesNeverInsideACharacter) {
  EXPECT_EQ(single_line("abcdef", 4), "abcd");
  EXPECT_EQ(single_line("ab\u00e4", 3), "ab");  // the 2-byte character does not fit
  EXPECT_EQ(single_line("ab\u00e4", 4), "ab\u00e4");
  EXPECT_EQ(single_line("\xff\xff\xff", 2), "??");
  EXPECT_EQ(single_line("", 0), "");
}

}  // namespace
}  // namespace cellmap
