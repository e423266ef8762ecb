// SPDX-License-Identifier: Apache-2.0
// The cell pipeline's config: its sections and the settling and gathering policies, read from the `change`
// section (settle_sweeps, gather_sweeps).
#include <gtest/gtest.h>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

std::string error_of(const std::string& yaml) {
  try {
    YamlMap root = YamlMap::parse(yaml, "cell.yaml");
    (void)CellPipelineConfig::from_yaml(root);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(CellPipelineConfigTest, ReadsItsSectionsWithSettleSweepsInTheChangeSection) {
  YamlMap root = YamlMap::parse(
      "cell: press-3\n"
      "occupancy: {resolution: 0.05}\n"
      "change:\n  persist_sweeps: 5\n  margin: 0.1\n  min_voxels: 3\n  settle_sweeps: 7\n  gather_sweeps: 2\n"
      "segment: {region_growing: {gap: 0.05}}\n"
      "reconcile: {min_overlap: 0.5}\n",
      "cell.yaml");
  const CellPipelineConfig c = CellPipelineConfig::from_yaml(root);
  EXPECT_DOUBLE_EQ(c.occupancy.resolution, 0.05);
  EXPECT_EQ(c.change.persist_sweeps, 5);
  EXPECT_DOUBLE_EQ(c.change.margin, 0.1);
  EXPECT_EQ(c.change.min_voxels, 3);
  EXPECT_EQ(c.settle_sweeps, 7);
  EXPECT_EQ(c.gather_sweeps, 2);
  EXPECT_DOUBLE_EQ(c.segment.region_growing.gap, 0.05);
  EXPECT_DOUBLE_EQ(c.reconcile.min_overlap, 0.5);
  // Only its own sections are read: the caller's other keys are left for the caller.
  EXPECT_THROW(root.expect_all_read(), Error);
  (void)root.get<std::string>("cell", "");
  EXPECT_NO_THROW(root.expect_all_read());
}

TEST(CellPipelineConfigTest, DefaultsAndErrorsNameTheKey) {
  EXPECT_EQ(CellPipelineConfig{}.settle_sweeps, 15);
  EXPECT_EQ(CellPipelineConfig{}.gather_sweeps, 0);
  EXPECT_EQ(error_of("change:\n  gather_sweeps: 1001\n"),
            "cell.yaml: change.gather_sweeps: must be an integer in [0, 1000], got 1001");
  EXPECT_EQ(error_of("change:\n  settle_sweeps: -1\n"),
            "cell.yaml: change.settle_sweeps: must be an integer in [0, 100000], got -1");
  EXPECT_EQ(error_of("change:\n  settle: 2\n"), "cell.yaml: change.settle: unknown key");
  EXPECT_EQ(error_of("reconcile: {min_overlap: 2}\n").rfind("cell.yaml: reconcile.min_overlap:", 0), 0u)
      << error_of("reconcile: {min_overlap: 2}\n");
  EXPECT_EQ(error_of("reconcile: {overlap: 0.5}\n"), "cell.yaml: reconcile.overlap: unknown key");
  CellPipelineConfig bad;
  bad.settle_sweeps = -1;
  EXPECT_THROW(CellPipeline{bad}, Error);
}

}  // namespace
}  // namespace cellmap
