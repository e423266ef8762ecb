// SPDX-License-Identifier: Apache-2.0
#include "acquisition.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "camera_input.hpp"
#include "cellmap/cell/frame_grouper.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/common/parallel.hpp"
#include "cellmap/transport/scene_edits.hpp"
#include "simulated_cell.hpp"

namespace cellmap::daemon {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// Applied scene edits logged per second at most: `cellmap inject` in a loop must not flood the log.
constexpr std::size_t kEditLinesPerSecond = 10;

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
        cell_(config.sources, config.robot),
        edits_(participant, cell_name_, inside(cell_), refuse(output.refusals)),
        output_(output),
        sweep_period_(config.sweep_period) {
    for (const SourceConfig& source : config.sources) sensors_.push_back(source.sensor);
  }

  void run(const std::atomic<bool>& stop, std::uint64_t max_sweeps) override {
    double stamp = 0.0;
    for (std::uint64_t sweeps = 0; !stop;) {
      const auto start = Clock::now();
      // Sweeps as fast as processed still cover one pass of the plan each in the motion's time.
      const double duration = sweep_period_ > 0 ? sweep_period_.load() : cell_.pass_duration();
      if (deliver(stamp, duration, stop)) stamp += duration;
      cpu_ = cpu_seconds_with_helpers();  // the renderer splits frames over threads
      if (max_sweeps > 0 && ++sweeps >= max_sweeps) return;
      // The period is read on every turn: a period changed by SIGHUP applies at once, not after the old one.
      while (!stop && Clock::now() < start + seconds(sweep_period_.load()))
        std::this_thread::sleep_for(milliseconds(10));
    }
  }

  [[nodiscard]] std::string describe() const override {
    return "sim (sensor '" + cell_.sensor_names() + "', " + std::to_string(cell_.scene().obstacles.size()) +
           " obstacles" + (cell_.scene().motion ? ", the robot moving" : "") + ")";
  }
  [[nodiscard]] std::optional<Robot> robot() const override { return cell_.robot(); }
  [[nodiscard]] std::uint64_t dropped_frames() const override { return dropped_; }
  [[nodiscard]] double cpu_seconds() const override { return cpu_; }
  void set_sweep_period(double seconds) override { sweep_period_ = seconds; }

 private:
  // Applies the edits that arrived, renders the next sweep and hands it over; false if that failed. A
  // simulated sweep's frames wait for room rather than be dropped: the simulation can wait for the thread
  // that fuses them (a line scanner's sweep has more frames than the queue holds), so a sweep is fused
  // whole or, should the sweeps wait too long for re-segmentation, dropped whole.
  bool deliver(double stamp, double duration, const std::atomic<bool>& stop) {
    try {
      apply_edits();
      for (SweepFrame& frame : cell_.next_sweep(stamp, duration).frames) {
        while (!stop && !output_.frames.wait_for_room(milliseconds(100))) {
        }
        output_.frames.put(std::move(frame));
      }
      output_.frames.end_sweep();
      dropped_ = cell_.dropped_frames();
      for (const std::string& sensor : sensors_) output_.health.set_sensor(sensor, SourceState::kConnected);
      return true;
    } catch (const Error& e) {
      for (const std::string& sensor : sensors_)
        output_.health.set_sensor(sensor, SourceState::kError, e.what());
      spdlog::error("sweep source: {}", e.what());
      return false;
    }
  }

  void apply_edits() {
    for (const transport::SceneEdit& edit : edits_.take()) {
      if (!edit.cell.empty() && edit.cell != cell_name_) continue;
      try {
        const std::string applied = "scene edit applied: " + cell_.apply(edit);
        if (const auto line = edit_lines_.admit(applied)) spdlog::info("{}", *line);
      } catch (const Error& e) {
        output_.refusals.refuse(e.what());
      }
    }
  }

  std::string cell_name_;
  SimulatedCell cell_;
  transport::SceneEditReader edits_;
  LogBudget edit_lines_{kEditLinesPerSecond, std::chrono::seconds(1)};
  AcquisitionOutput output_;
  std::vector<std::string> sensors_;
  std::atomic<double> sweep_period_;
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<double> cpu_{0.0};  // the acquisition thread's
};

// A replay played as fast as processed must lose no sweep.
bool played_fastest(const SourceConfig& source) {
  const auto* replay = std::get_if<ReplayConfig>(&source.camera.source);
  return replay != nullptr && replay->playback == ReplayConfig::Playback::kFastest;
}

// One camera's thread: its frames posed and grouped (with the other cameras') into sweeps; the camera's own
// back-off paces retries.
class CameraLoop final {
 public:
  CameraLoop(const SourceConfig& config, std::unique_ptr<DepthSource> source, const RobotInput* robot,
             AcquisitionOutput output)
      : camera_(config, std::move(source), robot), kind_(to_string(config.kind)), output_(output) {}

  void open() {
    const SourceStatus opened = camera_.open();
    reported_ = opened;
    if (opened.state == SourceState::kConnected) {
      spdlog::info("camera '{}': streaming", camera_.name());
      if (camera_.recorded_poses() > 0)
        spdlog::info("camera '{}': {} recorded robot poses", camera_.name(), camera_.recorded_poses());
    } else {
      spdlog::warn("camera '{}': {}", camera_.name(), sensor_text(opened.state, opened.reason));
    }
    output_.health.set_sensor(camera_.name(), opened.state, opened.reason);
  }

  // One turn: the frames posed in it, or none after an error (logged).
  std::vector<SweepFrame> step() {
    try {
      return camera_.step(milliseconds(100));
    } catch (const Error& e) {
      spdlog::error("camera '{}': {}", camera_.name(), e.what());
      std::this_thread::sleep_for(milliseconds(100));
      return {};
    }
  }

  // Logs and reports a change of the camera's state; true while it streams.
  bool report_state() {
    const SourceStatus now = camera_.status();
    if (now.state != reported_.state || now.reason != reported_.reason) {
      if (now.state == SourceState::kConnected) {
        spdlog::info("camera '{}': streaming", camera_.name());
      } else {
        spdlog::warn("camera '{}': {}; keeping version {}", camera_.name(),
                     sensor_text(now.state, now.reason), output_.published_version.load());
      }
      output_.health.set_sensor(camera_.name(), now.state, now.reason);
      reported_ = now;
    }
    streaming_ = now.state == SourceState::kConnected;
    return streaming_;
  }
  [[nodiscard]] bool streaming() const { return streaming_; }
  // The camera thread's CPU seconds with its source's helpers (a replay's reader), as it last noted them
  // (note_cpu(), on the camera thread).
  void note_cpu() { cpu_ = cpu_seconds_with_helpers(); }
  [[nodiscard]] double cpu_seconds() const { return cpu_; }

  // Frames dropped for want of a pose, logged at most once a second.
  void report_drops(const RobotInput* robot, double pose_tolerance) {
    if (camera_.dropped_frames() <= drops_logged_ || Clock::now() < next_drop_log_) return;
    spdlog::warn(
        "camera '{}': {} frames dropped without a robot pose within {} s ({} {} received, {} refused)",
        camera_.name(), camera_.dropped_frames(), pose_tolerance, robot ? robot->received() : 0,
        robot ? robot->what() : "recorded poses", robot ? robot->rejected() : 0);
    drops_logged_ = camera_.dropped_frames();
    next_drop_log_ = Clock::now() + std::chrono::seconds(1);
  }

  [[nodiscard]] const CameraInput& camera() const { return camera_; }
  [[nodiscard]] std::string describe() const { return kind_ + " (camera '" + camera_.name() + "')"; }
  [[nodiscard]] const std::string& name() const { return camera_.name(); }

 private:
  CameraInput camera_;
  std::string kind_;
  AcquisitionOutput output_;
  SourceStatus reported_;
  std::atomic<bool> streaming_{true};
  std::atomic<double> cpu_{0.0};
  std::uint64_t drops_logged_ = 0;
  Clock::time_point next_drop_log_ = Clock::now();
};

// The cell's cameras, each on a thread of its own, their posed frames grouped into one stream of sweeps; a
// thread takes the robot's samples (live cameras).
class CameraAcquisition final : public Acquisition {
 public:
  CameraAcquisition(const DaemonConfig& config, const dds::Participant& participant, AcquisitionOutput output)
      : output_(output),
        grouper_(config.sources.front().grouping),
        pose_tolerance_(config.sources.front().camera.pose_tolerance),
        robot_model_(config.robot) {
    const bool live = std::any_of(config.sources.begin(), config.sources.end(),
                                  [](const SourceConfig& s) { return !is_replay(s); });
    if (live) {
      robot_.emplace(config.robot, pose_tolerance_, participant, config.cell, config.ros2.joint_states,
                     refuse(output.refusals));
    }
    lossless_ = std::all_of(config.sources.begin(), config.sources.end(), played_fastest);
    for (const SourceConfig& source : config.sources) {
      loops_.push_back(std::make_unique<CameraLoop>(source,
                                                    make_source(source, participant, refuse(output.refusals)),
                                                    robot_ ? &*robot_ : nullptr, output));
    }
  }

  void run(const std::atomic<bool>& stop, std::uint64_t max_sweeps) override {
    std::atomic<bool> done{false};
    std::thread robot([&] {
      name_this_thread("robot state");
      while (robot_ && !stop && !done) robot_->pump(milliseconds(100));
    });
    std::vector<std::thread> cameras;
    std::atomic<std::size_t> ended{0};
    for (auto& loop : loops_) {
      cameras.emplace_back([&, camera = loop.get()] {
        name_this_thread("cam " + camera->name());
        run_camera(*camera, stop, done, ended, max_sweeps);
      });
    }
    for (std::thread& camera : cameras) camera.join();
    done = true;
    robot.join();
  }

  [[nodiscard]] std::string describe() const override {
    std::string text;
    for (const auto& loop : loops_) text += (text.empty() ? "" : ", ") + loop->describe();
    return text;
  }
  [[nodiscard]] std::optional<Robot> robot() const override { return robot_model_; }
  [[nodiscard]] std::uint64_t dropped_frames() const override {
    std::uint64_t dropped = 0;
    for (const auto& loop : loops_) dropped += loop->camera().dropped_frames();
    return dropped;
  }
  [[nodiscard]] double cpu_seconds() const override {
    double cpu = 0.0;
    for (const auto& loop : loops_) cpu += loop->cpu_seconds();
    return cpu;
  }
  [[nodiscard]] bool lossless() const override { return lossless_; }

 private:
  static bool is_replay(const SourceConfig& s) {
    return std::holds_alternative<ReplayConfig>(s.camera.source);
  }

  // A camera's thread. With max_sweeps, every thread ends once that many sweeps went out or every camera's
  // recording ended (its last sweep flushed).
  void run_camera(CameraLoop& loop, const std::atomic<bool>& stop, std::atomic<bool>& done,
                  std::atomic<std::size_t>& ended, std::uint64_t max_sweeps) {
    loop.open();
    bool counted_end = false;
    while (!stop && !done) {
      std::vector<SweepFrame> frames = loop.step();
      loop.report_state();
      loop.report_drops(robot_ ? &*robot_ : nullptr, pose_tolerance_);
      // The open sweep is closed by the next frame of any camera; when none streams, nothing will close it.
      const bool none_streaming =
          std::none_of(loops_.begin(), loops_.end(), [](const auto& l) { return l->streaming(); });
      if (group(std::move(frames), none_streaming, stop, max_sweeps)) done = true;
      loop.note_cpu();
      if (max_sweeps > 0 && !counted_end && loop.camera().status().state == SourceState::kEnded) {
        counted_end = true;
        if (++ended == loops_.size()) done = true;
      }
    }
  }

  // Delivers the frames with the ends of the sweeps they close (and of the open one when a camera stopped
  // streaming); true once max_sweeps were ended.
  bool group(std::vector<SweepFrame> frames, bool flush, const std::atomic<bool>& stop,
             std::uint64_t max_sweeps) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (SweepFrame& frame : frames) {
      const FramePlace place = grouper_.place(frame.frame.sensor, frame.frame.stamp);
      if (place.ends_open_sweep && end_sweep(max_sweeps)) return true;
      // A replay played as fast as processed must lose no frame: wait for the thread that fuses them.
      while (lossless_ && !stop && !output_.frames.wait_for_room(milliseconds(100))) {
      }
      output_.frames.put(std::move(frame));
      if (place.completes_sweep && end_sweep(max_sweeps)) return true;
    }
    return flush && grouper_.flush() && end_sweep(max_sweeps);
  }

  // Ends the open sweep in the queue; true once max_sweeps were ended.
  bool end_sweep(std::uint64_t max_sweeps) {
    output_.frames.end_sweep();
    return max_sweeps > 0 && ++delivered_ >= max_sweeps;
  }

  AcquisitionOutput output_;
  std::mutex mutex_;  // guards grouper_ and delivered_
  FrameGrouper grouper_;
  std::uint64_t delivered_ = 0;  // sweeps ended
  double pose_tolerance_;
  std::optional<Robot> robot_model_;
  std::optional<RobotInput> robot_;  // live cameras only
  bool lossless_ = false;            // replays played as fast as processed: no frame is dropped
  std::vector<std::unique_ptr<CameraLoop>> loops_;
};

}  // namespace

std::unique_ptr<Acquisition> make_acquisition(const DaemonConfig& config, const dds::Participant& participant,
                                              AcquisitionOutput output) {
  if (!config.simulated()) return std::make_unique<CameraAcquisition>(config, participant, output);
  return std::make_unique<SimAcquisition>(config, participant, output);
}

}  // namespace cellmap::daemon
