// SPDX-License-Identifier: Apache-2.0
#include "cellmap/config/yaml_map.hpp"

#include <gtest/gtest.h>

#include "support/test_support.hpp"

#include <functional>
#include <set>
#include <string>

namespace cellmap {
namespace {

using test::error_of;

TEST(YamlMapTest, ReadsValuesAndDefaults) {
  YamlMap root = YamlMap::parse("a: 2.5\nsub:\n  k: 7\n", "cfg.yaml");
  EXPECT_DOUBLE_EQ(root.number("a", 1.0, 0.0, 10.0), 2.5);
  EXPECT_DOUBLE_EQ(root.number("missing", 1.0, 0.0, 10.0), 1.0);
  YamlMap sub = root.child("sub");
  EXPECT_EQ(sub.integer("k", 0, 1, 100), 7);
  EXPECT_NO_THROW(sub.expect_all_read());
  EXPECT_NO_THROW(root.expect_all_read());
}

TEST(YamlMapTest, KeyLogRecordsEveryKeyReadOrAskedAboutWithItsPath) {
  YamlMap root = YamlMap::parse("a: 2.5\nsub:\n  k: 7\n", "cfg.yaml");
  (void)root.number("before", 1.0, 0.0, 10.0);  // read before the log: not recorded
  const YamlKeyLog log;
  (void)root.number("a", 1.0, 0.0, 10.0);
  (void)root.get<std::string>("absent", "");
  (void)root.has("optional");
  (void)root.child("sub").integer("k", 0, 1, 100);
  {
    const YamlKeyLog inner;  // the innermost log records; the outer one sees nothing meanwhile
    (void)root.has("inner_only");
    EXPECT_EQ(inner.keys(), (std::set<std::string>{"inner_only"}));
  }
  EXPECT_EQ(log.keys(), (std::set<std::string>{"a", "absent", "optional", "sub", "sub.k"}));
}

TEST(YamlMapTest, UnknownKeyIsNamedWithItsPath) {
  YamlMap root = YamlMap::parse("sub:\n  k: 7\n  typo: 1\n", "cfg.yaml");
  YamlMap sub = root.child("sub");
  (void)sub.integer("k", 0, 1, 100);
  EXPECT_EQ(error_of([&] { sub.expect_all_read(); }), "cfg.yaml: sub.typo: unknown key");
}

TEST(YamlMapTest, OutOfRangeAndWrongTypeNameTheKey) {
  YamlMap root = YamlMap::parse("gap: -1\nname: [1, 2]\nk: 2.5\n", "cfg.yaml");
  EXPECT_EQ(error_of([&] { (void)root.number("gap", 0.1, 0.0, 1.0); }),
            "cfg.yaml: gap: must be in [0, 1], got -1");
  EXPECT_EQ(error_of([&] { (void)root.require<std::string>("name"); }), "cfg.yaml: name: has the wrong type");
  EXPECT_EQ(error_of([&] { (void)root.integer("k", 1, 1, 10); }), "cfg.yaml: k: has the wrong type");
  EXPECT_EQ(error_of([&] { (void)root.require<double>("absent"); }), "cfg.yaml: absent: is required");
}

TEST(YamlMapTest, NonFiniteNumbersAreRejected) {
  YamlMap root = YamlMap::parse("gap: .nan\nsize: .inf\n", "cfg.yaml");
  EXPECT_NE(error_of([&] { (void)root.number("gap", 0.1, 0.0, 1.0); }), "");
  EXPECT_NE(error_of([&] { (void)root.number("size", 0.1, 0.0, 1e9); }), "");
}

TEST(YamlMapTest, SyntaxErrorGivesLine) {
  EXPECT_EQ(error_of([] {
              (void)YamlMap::parse("a: [1, 2\nb: 3\n", "bad.yaml");
            }).rfind("bad.yaml: YAML syntax error at line", 0),
            0u);
}

TEST(YamlMapTest, NonMapDocumentIsRejected) {
  EXPECT_EQ(error_of([] { (void)YamlMap::parse("- 1\n- 2\n", "list.yaml"); }),
            "list.yaml: document: must be a mapping of keys");
  EXPECT_NO_THROW((void)YamlMap::parse("", "empty.yaml"));
}

// One pose schema for every pose in the configuration files; `translation` (the daemon's older X_ES spelling)
// reads as `position`.
TEST(YamlMapTest, PoseReadsPositionOrTranslationAndRotation) {
  YamlMap root = YamlMap::parse(
      "a: {position: [1, 2, 3], rotation: [0.7071067811865476, 0, 0, 0.7071067811865476]}\n"
      "b: {translation: [1, 2, 3]}\n",
      "cfg.yaml");
  const Eigen::Isometry3d a = root.pose("a");
  EXPECT_TRUE(a.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE((a.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(root.pose("b").translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(root.pose("absent").isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_NO_THROW(root.expect_all_read());
}

TEST(YamlMapTest, PoseErrorsNameTheKey) {
  YamlMap root = YamlMap::parse(
      "both: {position: [0, 0, 0], translation: [0, 0, 0]}\n"
      "short: {position: [0, 0]}\n"
      "tilted: {rotation: [1, 1, 0, 0]}\n"
      "typo: {positon: [0, 0, 0]}\n",
      "cfg.yaml");
  EXPECT_EQ(error_of([&] { (void)root.pose("both"); }),
            "cfg.yaml: both.translation: is another spelling of position: give one of them");
  EXPECT_EQ(error_of([&] { (void)root.pose("short"); }),
            "cfg.yaml: short.position: must have 3 numbers, got 2");
  EXPECT_EQ(error_of([&] {
              (void)root.pose("tilted");
            }).rfind("cfg.yaml: tilted.rotation: must be a unit quaternion", 0),
            0u);
  EXPECT_EQ(error_of([&] { (void)root.pose("typo"); }), "cfg.yaml: typo.positon: unknown key");
}

// Found by fuzzing (fuzz_daemon_config): a key that is a map or a list made the readers throw yaml-cpp's
// conversion error instead of ours.
TEST(YamlMapTest, KeysMustBePlainNames) {
  EXPECT_EQ(error_of([] { (void)YamlMap::parse("a: 1\n? [x, y]\n: 2\n", "cfg.yaml"); }),
            "cfg.yaml: document: the key at line 2 is not a plain name");
  YamlMap root = YamlMap::parse("sub:\n  ? {k: 1}\n  : 2\n", "cfg.yaml");
  EXPECT_EQ(error_of([&] { (void)root.child("sub"); }),
            "cfg.yaml: sub: the key at line 2 is not a plain name");
}

// A key is echoed in messages; whatever it holds, the message stays one line.
TEST(YamlMapTest, MessagesStayOneLine) {
  YamlMap root = YamlMap::parse("\"a\\nb\": 1\n", "cfg.yaml");
  EXPECT_EQ(error_of([&] { root.expect_all_read(); }), "cfg.yaml: a?b: unknown key");
}

}  // namespace
}  // namespace cellmap
