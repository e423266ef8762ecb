// SPDX-License-Identifier: Apache-2.0
#include "cellmap/cell/cell_pipeline.hpp"

namespace cellmap {
namespace {

ReconcileParams read_reconcile(YamlMap section) {
  ReconcileParams o;
  o.min_overlap = section.number("min_overlap", o.min_overlap, 0.0, 1.0);
  o.position_tolerance = section.number("position_tolerance", o.position_tolerance, 0.0, 1.0);
  o.rotation_tolerance = section.number("rotation_tolerance", o.rotation_tolerance, 0.0, 3.2);
  o.redundant_tolerance = section.number("redundant_tolerance", o.redundant_tolerance, 0.0, 1.0);
  section.expect_all_read();
  return o;
}

}  // namespace

CellPipelineConfig CellPipelineConfig::from_yaml(YamlMap& root) {
  // Every section is taken from the root before any is read: a reader that goes on past a bad section
  // (cellmapd --check) then does not report the sections after it as unknown keys.
  YamlMap occupancy = root.child("occupancy");
  YamlMap change = root.child("change");
  YamlMap segment = root.child("segment");
  YamlMap reconcile = root.child("reconcile");
  YamlMap self_filter = root.child("self_filter");
  YamlMap unknown = root.child("unknown");
  CellPipelineConfig c;
  c.occupancy = OccupancyConfig::from_yaml(occupancy);
  // settle_sweeps, gather_sweeps and gather_removals sit in the `change` section (where operators look for
  // them) but are the pipeline's policies: read them here, the rest of the section by the change detector's
  // reader.
  c.settle_sweeps = static_cast<int>(change.integer("settle_sweeps", c.settle_sweeps, 0, 100000));
  c.gather_sweeps = static_cast<int>(change.integer("gather_sweeps", c.gather_sweeps, 0, 1000));
  c.gather_removals = change.get<bool>("gather_removals", c.gather_removals);
  c.change = ChangeConfig::from_yaml(change);
  c.segment = SegmentConfig::from_yaml(segment);
  // cover_every_version is the pipeline's policy too, read the same way.
  c.cover_every_version = reconcile.get<bool>("cover_every_version", c.cover_every_version);
  c.reconcile = read_reconcile(reconcile);
  c.self_filter = SelfFilterConfig::from_yaml(self_filter);
  c.unknown = UnknownSpaceConfig::from_yaml(unknown);
  if (!c.unknown.workspace && c.segment.workspace) c.unknown.workspace = c.segment.workspace->bounds();
  return c;
}

}  // namespace cellmap
