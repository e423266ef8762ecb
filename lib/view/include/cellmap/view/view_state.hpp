// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the viewer's web page shows, kept by the server as DDS brings it: per cell the boxes (with the version
// that last changed each), a timeline of versions, the daemon's status and whether a daemon is there at all,
// and the latest optional layers. Each change returns the JSON message that tells the pages about it.
//
// The page protocol (WebSocket text frames, one JSON object each, server → page):
//   {"type":"state", "domain", "cell_filter", "cells":[CELL...]}     everything, sent to a page that connects
//   {"type":"version", "cell", "from_version", "to_version", "stamp_ns", "received_ns",
//    "added":[BOX...], "modified":[BOX...], "removed":[id...]}      a new version of a cell's environment
//   {"type":"status", STATUS}                                        a daemon's report, or that it is gone
//   {"type":"voxels", "cell", "sweep", "stamp_ns", "resolution", "runs":[x,y,z,length, ...]}
//   {"type":"regions", "cell", "sweep", "stamp_ns", "regions":[{"min", "max", "appeared", "vanished"}...]}
//   {"type":"sensors", "cell", "sweep", "stamp_ns", "views":[{"sensor", "position", "rotation" [w,x,y,z],
//    "max_range", "closed", "outline":[[x,y,z]...]}...]}  (outline: unit rays in the sensor frame; empty and
//    max_range 0 when unknown)
//   {"type":"robot", "cell", "sweep", "stamp_ns", "padding_scale", "padding", "shapes":[{"link", "carried",
//    "position", "rotation" [w,x,y,z], "kind", and by kind "half_extents" (box), "radius", "half_length"
//    (cylinder, axis along its z), "radius" (sphere), "vertices":[x,y,z, ...] (0.1 mm), "triangles":[i,j,k,
//    ...] (mesh)}...]}  (the shape's frame in the cell frame; vertices in the shape's frame)
// CELL = {"cell", "version", "stamp_ns", "boxes":[BOX...], "timeline":[ENTRY...], "status":STATUS|null}
// BOX = {"id", "center", "half_extents", "rotation" [w,x,y,z], "points", "space", "changed_in"} where space
//   is "occupied" (an obstacle box) or "unknown" (space no sensor has observed) and changed_in is the version
//   that added or last modified the box, null if that was before the viewer joined
// ENTRY = {"from_version", "to_version", "stamp_ns", "received_ns", "added", "modified", "removed"} (counts)
// STATUS = {"cell", "daemon" (false once it is gone), "state", "reason", "sensors":[{"name","state"}...],
//   "last_sweep_ns", "sweeps", "dropped_frames", "refused_inputs", "boxes", "version"}
// Page → server: {"type":"layers", "voxels":bool, "regions":bool, "sensors":bool, "robot":bool} (which layers
// this page shows; a missing key is false) and
// {"type":"resync"} (the page missed a version: it gets a "state" again).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "cellmap/environment/environment.hpp"
#include "cellmap/transport/layers.hpp"
#include "cellmap/transport/messages.hpp"

namespace cellmap::view {

/// One status report as a JSON object (the fields of cellmap/status, docs/dds.md): {"cell", "state",
/// "reason", "sensors":[{"name","state"}...], "last_sweep_ns", "sweeps", "dropped_frames", "refused_inputs",
/// "boxes", "version"}. The page's STATUS is this with "daemon"; `cellmap status --json` lists them.
[[nodiscard]] std::string status_json(const transport::CellStatus& status);

/// A layer's name in the page protocol: its message type and its key in a "layers" request.
[[nodiscard]] const char* layer_name(transport::Layer layer);

/// Thread-safe: DDS callbacks update it while the web server reads it.
class ViewState final {
 public:
  /// @param cell_filter the one cell followed, or "" for every cell on the domain
  /// @param timeline_length versions kept per cell (the oldest are dropped)
  ViewState(std::uint32_t domain, std::string cell_filter, std::size_t timeline_length = 200);

  /// A cell's local copy reached `env` by `delta` (the EnvironmentSubscriber callback); `received_ns` is when
  /// the viewer got it (ns since the Unix epoch). Returns the "version" message.
  std::string on_version(const Environment& env, const EnvironmentDelta& delta, std::int64_t received_ns);
  /// A daemon's status report. Returns the "status" message.
  std::string on_status(const transport::CellStatus& status);
  /// The cell's daemon is gone (its status writer left or its lease expired). Returns the "status" message,
  /// with daemon false and the last report's fields.
  std::string on_daemon_gone(const std::string& cell);
  /// A layer arrived. Returns its message ("voxels", "regions", "sensors" or "robot"), which is also kept for
  /// pages that ask later.
  std::string on_layer(const transport::LayerMessage& layer);

  /// The "state" message: every cell as it is now.
  [[nodiscard]] std::string state() const;
  /// The latest message of `layer` for every cell (for a page that starts showing it).
  [[nodiscard]] std::vector<std::string> layers(transport::Layer layer) const;
  /// Whether the cell is followed and a daemon reported for it and has not gone since.
  [[nodiscard]] bool daemon(const std::string& cell) const;
  /// The cells known so far (a status or a version came), sorted.
  [[nodiscard]] std::vector<std::string> cells() const;

 private:
  struct TimelineEntry {
    std::uint64_t from_version = 0, to_version = 0;
    std::int64_t stamp_ns = 0, received_ns = 0;
    std::size_t added = 0, modified = 0, removed = 0;
  };
  struct Cell {
    std::optional<Environment> environment;
    std::map<std::uint64_t, std::uint64_t> changed_in;  // box id → version that added or last modified it
    std::deque<TimelineEntry> timeline;
    std::optional<transport::CellStatus> status;
    bool daemon = false;
    std::map<transport::Layer, std::string> layers;  // the latest message of each layer
  };

  [[nodiscard]] bool followed(const std::string& cell) const;

  std::uint32_t domain_;
  std::string cell_filter_;
  std::size_t timeline_length_;
  mutable std::mutex mutex_;
  std::map<std::string, Cell> cells_;  // guarded by mutex_
};

}  // namespace cellmap::view
