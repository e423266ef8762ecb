// SPDX-License-Identifier: Apache-2.0
#include "versions.hpp"

#include <spdlog/spdlog.h>

#include <chrono>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"

namespace cellmap::daemon {
namespace {

std::optional<std::string> read_map_state(const RecoveredState& recovered) {
  if (!recovered.blob) {
    if (recovered.environment.version() > 0)
      spdlog::warn("state: no map state saved; starting with an empty map");
    return std::nullopt;
  }
  try {
    return read_file(*recovered.blob);
  } catch (const Error& e) {
    spdlog::warn("state: {}; starting with an empty map", e.what());
    return std::nullopt;
  }
}

}  // namespace

CellPipeline recover_pipeline(const CellPipelineConfig& config, const RecoveredState& recovered) {
  for (const std::string& problem : recovered.problems) spdlog::warn("state: {}", problem);
  const std::vector<Box>& boxes = recovered.environment.boxes();
  const std::optional<std::string> map_state = read_map_state(recovered);
  if (map_state) {
    try {
      CellPipeline pipeline(config, boxes, recovered.next_box_id, map_state);
      if (pipeline.next_box_id() > recovered.next_box_id) {
        spdlog::info("state: the map state (an older format) carried the box-id counter {}; ids go on there",
                     pipeline.next_box_id());
      }
      return pipeline;
    } catch (const Error& e) {
      spdlog::warn("state: {}; starting with an empty map", e.what());
    }
  }
  if (recovered.environment.version() > 0) {
    spdlog::info("state: {} boxes kept, new box ids from {} on", boxes.size(), recovered.next_box_id);
  }
  return CellPipeline(config, boxes, recovered.next_box_id);
}

VersionKeeper::VersionKeeper(VersionStore& store, Publish publish, WallClock clock)
    : store_(store),
      publish_(std::move(publish)),
      clock_(std::move(clock)),
      saved_(store.recovered().environment),
      published_(store.recovered().environment.cell()) {}

void VersionKeeper::resume(const CellPipeline& pipeline) {
  if (saved_.version() == 0) return;
  try {
    saved_ = store_.resume(next_stamp(), pipeline.map_state());
    resumed_ = true;
  } catch (const Error& e) {
    save_owed_ = true;
    failed("version " + std::to_string(store_.next_version()) + " not saved: " + e.what());
    return;
  }
  publish_saved();
}

void VersionKeeper::flush(const CellPipeline& pipeline) {
  publish_boxes(pipeline);
  save_map_state(pipeline);
}

void VersionKeeper::publish_boxes(const CellPipeline& pipeline) {
  if (save_due(pipeline.environment_boxes())) save(pipeline);
  if (saved_.version() > published_.version()) publish_saved();
}

void VersionKeeper::save_map_state(const CellPipeline& pipeline) {
  if (!map_state_owed_ || save_owed_) return;
  try {
    store_.attach_blob(saved_.version(), pipeline.map_state());
  } catch (const Error& e) {
    failed("map state of version " + std::to_string(saved_.version()) + " not saved: " + e.what());
    return;
  }
  map_state_owed_ = false;
  if (!fault_.empty() && saved_.version() == published_.version()) recovered();
}

bool VersionKeeper::save_due(const std::vector<Box>& boxes) {
  if (save_owed_) return true;
  if (!store_.holds_last_saved()) {
    spdlog::warn("state: version {} is no longer in {} (directory removed or emptied?); saving it again",
                 saved_.version(), store_.directory().string());
    return true;
  }
  const Environment candidate(saved_.cell(), saved_.version() + 1, saved_.stamp_ns(), boxes);
  return !diff(saved_, candidate).empty();
}

void VersionKeeper::save(const CellPipeline& pipeline) {
  const Environment next(saved_.cell(), store_.next_version(), next_stamp(), pipeline.environment_boxes());
  try {
    store_.save(next, std::nullopt, pipeline.next_box_id());
  } catch (const Error& e) {
    save_owed_ = true;
    failed("version " + std::to_string(next.version()) + " not saved: " + e.what());
    return;
  }
  save_owed_ = false;
  map_state_owed_ = true;
  resumed_ = false;
  saved_ = next;
}

// Persist first, then publish (save() ran before): a number subscribers saw is always on disk.
void VersionKeeper::publish_saved() {
  const EnvironmentDelta delta = diff(published_, saved_);
  try {
    publish_(saved_, delta);
  } catch (const Error& e) {
    failed("version " + std::to_string(saved_.version()) + " not published: " + e.what());
    return;
  }
  if (resumed_) {
    spdlog::info("resumed version {} with {} boxes", saved_.version(), saved_.boxes().size());
  } else {
    spdlog::info("version {}: {} added, {} modified, {} removed, {} boxes", saved_.version(),
                 delta.added.size(), delta.modified.size(), delta.removed.size(), saved_.boxes().size());
  }
  published_ = saved_;
  resumed_ = false;
  if (!fault_.empty()) recovered();
}

void VersionKeeper::recovered() {
  spdlog::info("version {} is out after {} failed attempts; running again", saved_.version(),
               failed_attempts_);
  fault_.clear();
  failed_attempts_ = 0;
}

// Logged when the reason changes, not at every retry: a full disk must not fill the log too.
void VersionKeeper::failed(const std::string& reason) {
  ++failed_attempts_;
  if (reason == fault_) return;
  fault_ = reason;
  spdlog::error("{}; subscribers keep version {}, retrying", reason, published_.version());
}

std::int64_t VersionKeeper::next_stamp() const {
  return std::max(clock_(), saved_.stamp_ns() + 1);
}

}  // namespace cellmap::daemon
