// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/scene_edits.hpp"

#include "cellmap/common/error.hpp"
#include "cellmap/transport/topics.hpp"
#include "wire.hpp"

namespace cellmap::transport {

SceneEditWriter::SceneEditWriter(const dds::Participant& participant, std::string cell)
    : cell_(std::move(cell)),
      topic_(participant, &cellmap_msg_SceneEdit_desc, kSceneEditTopic),
      writer_(participant, topic_, in_cell(scene_edit_qos(), cell_)) {}

bool SceneEditWriter::wait_for_reader(std::chrono::nanoseconds timeout) const {
  return writer_.wait_for_readers(1, timeout);
}

void SceneEditWriter::write(const SceneEdit& edit) const {
  if (edit.name.empty()) throw Error(std::string(kSceneEditTopic) + ": name: must not be empty");
  const bool for_every_cell = edit.cell.empty();
  if (for_every_cell != (cell_ == kEveryCell) || (!for_every_cell && edit.cell != cell_)) {
    throw Error(std::string(kSceneEditTopic) + ": an edit for " +
                (for_every_cell ? "every cell" : "cell '" + edit.cell + "'") + " on a writer for " +
                (cell_ == kEveryCell ? "every cell" : "cell '" + cell_ + "'"));
  }
  const wire::SceneEditSample sample(edit);
  writer_.write(sample.get());
}

bool SceneEditWriter::wait_for_acks(std::chrono::nanoseconds timeout) const {
  return writer_.wait_for_acks(timeout);
}

SceneEditReader::SceneEditReader(const dds::Participant& participant, const std::string& cell,
                                 InputLimits limits, OnRefused on_refused)
    : limits_(std::move(limits)),
      on_refused_(std::move(on_refused)),
      topic_(participant, &cellmap_msg_SceneEdit_desc, kSceneEditTopic),
      reader_(participant, topic_, in_cell(scene_edit_qos(), cell)),
      waitset_(participant) {
  waitset_.attach(reader_);
}

SceneEditReader::~SceneEditReader() {
  try {
    waitset_.detach(reader_);
  } catch (const Error&) {
    // Deleting the reader detaches it anyway.
  }
}

std::vector<SceneEdit> SceneEditReader::take(std::chrono::nanoseconds timeout) {
  if (timeout.count() > 0) waitset_.wait(timeout);
  std::vector<SceneEdit> edits;
  reader_.take_all([&](const void* sample, const dds_sample_info_t&) {
    try {
      SceneEdit edit = wire::from_wire(*static_cast<const cellmap_msg_SceneEdit*>(sample));
      check_limits(edit, limits_);
      edits.push_back(std::move(edit));
    } catch (const Error& e) {
      ++rejected_;
      if (on_refused_) on_refused_(e.what());
    }
  });
  return edits;
}

}  // namespace cellmap::transport
