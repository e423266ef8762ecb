#include "daemon_config.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap::daemon {
namespace {

std::string error_of(const std::string& yaml) {
  try {
    (void)DaemonConfig::parse(yaml, "my.yaml", "/etc/cellmap");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(DaemonConfigTest, BuiltInDefaultsAreTheShippedFile) {
  const DaemonConfig c = DaemonConfig::parse("", "empty.yaml", ".");
  EXPECT_EQ(c.cell, "cell-1");
  EXPECT_EQ(c.source.kind, "sim");
  EXPECT_TRUE(c.source.scene.empty());
  EXPECT_DOUBLE_EQ(c.occupancy.resolution, 0.02);
  EXPECT_EQ(c.change.persist_sweeps, 3);
  // The voxel-tuned segmentation of config/cellmapd.yaml, not the batch defaults of config/segment.yaml.
  EXPECT_EQ(c.segment.k, 26);
  EXPECT_DOUBLE_EQ(c.segment.region_growing.gap, 0.035);
}

TEST(DaemonConfigTest, FileOverlaysDefaultsKeyByKey) {
  const DaemonConfig c = DaemonConfig::parse(
      "cell: press-3\nsource: {scene: scenes/small.yaml}\nsegment: {region_growing: {gap: 0.05}}\n",
      "my.yaml", "/etc/cellmap");
  EXPECT_EQ(c.cell, "press-3");
  EXPECT_EQ(c.source.scene, std::filesystem::path("/etc/cellmap/scenes/small.yaml"));
  EXPECT_EQ(c.source.sensor, "kinect");  // untouched sibling key keeps its default
  EXPECT_DOUBLE_EQ(c.segment.region_growing.gap, 0.05);
  EXPECT_EQ(c.segment.k, 26);
}

TEST(DaemonConfigTest, ErrorsNameTheFileAndKey) {
  EXPECT_EQ(error_of("cel: x\n"), "my.yaml: cel: unknown key");
  EXPECT_EQ(error_of("change: {margin: -1}\n").rfind("my.yaml: change.margin:", 0), 0u)
      << error_of("change: {margin: -1}\n");
  EXPECT_EQ(error_of("source: {kind: kinect}\n"),
            "my.yaml: source.kind: must be sim (the only source cellmapd wires so far)");
  EXPECT_EQ(error_of("log_level: loud\n"),
            "my.yaml: log_level: must be one of trace, debug, info, warn, error");
  EXPECT_EQ(error_of("segment: {neighbours: {kk: 3}}\n").rfind("my.yaml: segment.neighbours.kk", 0), 0u)
      << error_of("segment: {neighbours: {kk: 3}}\n");
}

}  // namespace
}  // namespace cellmap::daemon
