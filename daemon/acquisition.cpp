#include "acquisition.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <optional>
#include <thread>

#include "camera_input.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/transport/scene_edits.hpp"
#include "simulated_cell.hpp"

namespace cellmap::daemon {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

// Readers report the DDS inputs they refuse here: counted in the status, logged at most once a second.
transport::OnRefused refuse(InputRefusals& refusals) {
  return [&refusals](const std::string& reason) { refusals.refuse(reason); };
}

// Scene edits must stay inside the simulated cell.
transport::InputLimits inside(const SimulatedCell& cell) {
  transport::InputLimits limits;
  limits.cell = Eigen::AlignedBox3d(cell.scene().cell.min, cell.scene().cell.max);
  return limits;
}

// The simulated cell: one sweep every sweep_period (or as fast as taken), scene edits applied between sweeps.
class SimAcquisition final : public Acquisition {
 public:
  SimAcquisition(const DaemonConfig& config, const dds::Participant& participant, AcquisitionOutput output)
      : cell_name_(config.cell),
        cell_(config.source),
        edits_(participant, inside(cell_), refuse(output.refusals)),
        output_(output),
        sweep_period_(config.sweep_period) {}

  void run(const std::atomic<bool>& stop, std::uint64_t max_sweeps) override {
    double stamp = 0.0;
    for (std::uint64_t sweeps = 0; !stop;) {
      const auto start = Clock::now();
      if (deliver(stamp)) stamp += sweep_period_;
      if (max_sweeps > 0 && ++sweeps >= max_sweeps) return;
      const auto next = start + seconds(sweep_period_.load());
      while (!stop && Clock::now() < next) std::this_thread::sleep_for(milliseconds(10));
    }
  }

  [[nodiscard]] std::string describe() const override {
    return "sim (sensor '" + cell_.sensor_name() + "', " + std::to_string(cell_.scene().obstacles.size()) +
           " obstacles)";
  }

  void set_sweep_period(double seconds) override { sweep_period_ = seconds; }

 private:
  // Applies the edits that arrived, renders the next sweep and hands it over; false if that failed.
  bool deliver(double stamp) {
    try {
      apply_edits();
      output_.mailbox.put(cell_.next_sweep(stamp));
      output_.health.set_sensor(SourceState::kConnected);
      return true;
    } catch (const Error& e) {
      output_.health.set_sensor(SourceState::kError, e.what());
      spdlog::error("sweep source: {}", e.what());
      return false;
    }
  }

  void apply_edits() {
    for (const transport::SceneEdit& edit : edits_.take()) {
      if (!edit.cell.empty() && edit.cell != cell_name_) continue;
      try {
        spdlog::info("scene edit applied: {}", cell_.apply(edit));
      } catch (const Error& e) {
        output_.refusals.refuse(e.what());
      }
    }
  }

  std::string cell_name_;
  SimulatedCell cell_;
  transport::SceneEditReader edits_;
  AcquisitionOutput output_;
  std::atomic<double> sweep_period_;
};

// One camera: sweeps come as its frames arrive and get their poses; the camera's own back-off paces retries.
class CameraAcquisition final : public Acquisition {
 public:
  CameraAcquisition(const DaemonConfig& config, const dds::Participant& participant, AcquisitionOutput output)
      : camera_(config.source, participant, config.cell, refuse(output.refusals)),
        output_(output),
        pose_tolerance_(config.source.camera.pose_tolerance) {
    const auto* replay = std::get_if<ReplayConfig>(&config.source.camera.source);
    lossless_ = replay != nullptr && replay->playback == ReplayConfig::Playback::kFastest;
    kind_ = to_string(config.source.kind);
  }

  void run(const std::atomic<bool>& stop, std::uint64_t max_sweeps) override {
    open();
    std::uint64_t delivered = 0;
    while (!stop) {
      for (Sweep& sweep : step()) {
        // A replay played as fast as processed must lose no sweep: wait for the processing thread.
        while (lossless_ && !stop && !output_.mailbox.wait_taken(milliseconds(100))) {
        }
        output_.mailbox.put(std::move(sweep));
        if (max_sweeps > 0 && ++delivered >= max_sweeps) return;
      }
      // --sweeps N on a recording shorter than N sweeps ends with the recording (its last sweep was flushed).
      if (max_sweeps > 0 && camera_.status().state == SourceState::kEnded) return;
      dropped_ = camera_.dropped_frames();
      report_state();
      report_drops();
    }
  }

  [[nodiscard]] std::string describe() const override { return kind_ + " (camera '" + camera_.name() + "')"; }
  [[nodiscard]] std::uint64_t dropped_frames() const override { return dropped_; }

 private:
  void open() {
    const SourceStatus opened = camera_.open();
    reported_ = opened;
    if (opened.state == SourceState::kConnected) {
      spdlog::info("camera '{}': streaming", camera_.name());
      if (camera_.poses_received() > 0)
        spdlog::info("camera '{}': {} recorded robot poses", camera_.name(), camera_.poses_received());
    } else {
      spdlog::warn("camera '{}': {}", camera_.name(), sensor_text(opened.state, opened.reason));
    }
    output_.health.set_sensor(opened.state, opened.reason);
  }

  std::vector<Sweep> step() {
    try {
      return camera_.step(milliseconds(100));
    } catch (const Error& e) {
      spdlog::error("camera '{}': {}", camera_.name(), e.what());
      std::this_thread::sleep_for(milliseconds(100));
      return {};
    }
  }

  // Logs and reports a change of the camera's state.
  void report_state() {
    const SourceStatus now = camera_.status();
    if (now.state == reported_.state && now.reason == reported_.reason) return;
    if (now.state == SourceState::kConnected) {
      spdlog::info("camera '{}': streaming", camera_.name());
    } else {
      spdlog::warn("camera '{}': {}; keeping version {}", camera_.name(), sensor_text(now.state, now.reason),
                   output_.published_version.load());
    }
    output_.health.set_sensor(now.state, now.reason);
    reported_ = now;
  }

  // Frames dropped for want of a pose, logged at most once a second.
  void report_drops() {
    if (camera_.dropped_frames() <= drops_logged_ || Clock::now() < next_drop_log_) return;
    spdlog::warn(
        "camera '{}': {} frames dropped without a robot pose within {} s ({} poses received, {} malformed)",
        camera_.name(), camera_.dropped_frames(), pose_tolerance_, camera_.poses_received(),
        camera_.poses_rejected());
    drops_logged_ = camera_.dropped_frames();
    next_drop_log_ = Clock::now() + std::chrono::seconds(1);
  }

  CameraInput camera_;
  AcquisitionOutput output_;
  double pose_tolerance_;
  std::string kind_;
  bool lossless_ = false;  // a replay played as fast as processed: no sweep is replaced in the mailbox
  SourceStatus reported_;
  std::atomic<std::uint64_t> dropped_{0};
  std::uint64_t drops_logged_ = 0;
  Clock::time_point next_drop_log_ = Clock::now();
};

}  // namespace

std::unique_ptr<Acquisition> make_acquisition(const DaemonConfig& config, const dds::Participant& participant,
                                              AcquisitionOutput output) {
  if (config.source.is_camera()) return std::make_unique<CameraAcquisition>(config, participant, output);
  return std::make_unique<SimAcquisition>(config, participant, output);
}

}  // namespace cellmap::daemon
