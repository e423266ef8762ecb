#include "cellmap/common/yaml_map.hpp"

#include <gtest/gtest.h>

#include "support/test_support.hpp"

#include <functional>

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

}  // namespace
}  // namespace cellmap
