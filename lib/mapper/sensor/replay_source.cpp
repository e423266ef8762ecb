// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sensor/replay_source.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/common/parallel.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/io/cloud_file.hpp"
#include "cellmap/sensor/depth_io.hpp"

namespace cellmap {
namespace {

constexpr const char* kPosesHeader = "file,stamp,x,y,z,qw,qx,qy,qz";

}  // namespace

std::vector<ReplayEntry> read_replay_poses(const std::string& path) {
  std::stringstream text(read_file(path));
  std::vector<ReplayEntry> entries;
  std::string line;
  bool have_header = false;
  for (int number = 1; std::getline(text, line); ++number) {
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    const std::string where = path + ":" + std::to_string(number);
    if (!have_header) {
      std::string header;
      for (const std::string& field : split(line, ',')) header += (header.empty() ? "" : ",") + field;
      if (header != kPosesHeader) throw Error(where + ": header must be '" + std::string(kPosesHeader) + "'");
      have_header = true;
      continue;
    }
    const std::vector<std::string> fields = split(line, ',');
    if (fields.size() != 9) throw Error(where + ": expected 9 fields, got " + std::to_string(fields.size()));
    if (fields[0].empty()) throw Error(where + ": file is empty");
    ReplayEntry entry;
    entry.file = fields[0];
    entry.stamp = parse_finite(fields[1], where + ": stamp");
    const Eigen::Vector3d p(parse_finite(fields[2], where + ": x"), parse_finite(fields[3], where + ": y"),
                            parse_finite(fields[4], where + ": z"));
    const Eigen::Quaterniond q(
        parse_finite(fields[5], where + ": qw"), parse_finite(fields[6], where + ": qx"),
        parse_finite(fields[7], where + ": qy"), parse_finite(fields[8], where + ": qz"));
    if (std::abs(q.norm() - 1.0) > 1e-3) {
      throw Error(where + ": quaternion [qw, qx, qy, qz] has norm " + std::to_string(q.norm()) +
                  ", expected 1");
    }
    if (!entries.empty() && !(entry.stamp > entries.back().stamp)) {
      throw Error(where + ": stamp " + fields[1] + " is not after the previous one");
    }
    entry.X_CE.linear() = q.normalized().toRotationMatrix();
    entry.X_CE.translation() = p;
    entries.push_back(entry);
  }
  if (!have_header) throw Error(path + ": empty; header must be '" + std::string(kPosesHeader) + "'");
  return entries;
}

void write_replay_poses(const std::string& path, const std::vector<ReplayEntry>& entries) {
  std::ostringstream out;
  out << kPosesHeader << "\n" << std::setprecision(17);
  for (const ReplayEntry& entry : entries) {
    const Eigen::Quaterniond q(entry.X_CE.linear());
    const Eigen::Vector3d& p = entry.X_CE.translation();
    out << entry.file << "," << entry.stamp << "," << p.x() << "," << p.y() << "," << p.z() << "," << q.w()
        << "," << q.x() << "," << q.y() << "," << q.z() << "\n";
  }
  write_file_atomically(path, out.str());
}

// Reads one asked-for frame at a time on a thread of its own, at the lowest CPU priority.
class ReplaySource::Reader final {
 public:
  explicit Reader(const ReplaySource& source) : source_(source), thread_([this] { run(); }) {}
  ~Reader() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  // Starts reading frame `index` unless it is already asked for.
  void ask(std::size_t index) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (asked_ == index) return;
      asked_ = index;
      started_ = false;
      outcome_.reset();
    }
    changed_.notify_all();
  }
  // Frame `index` (asked for) once read, waiting up to `patience` (real time: the read is real work) for the
  // read; nullopt if it is not read by then. Credits the calling thread with the read's CPU time.
  // @throws Error as the read did.
  std::optional<Frame> take(std::size_t index, std::chrono::milliseconds patience) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!changed_.wait_for(lock, patience, [&] { return asked_ == index && outcome_; })) return std::nullopt;
    Outcome outcome = std::move(*outcome_);
    outcome_.reset();
    asked_ = kNone;
    add_helper_cpu_seconds(outcome.cpu_seconds);
    if (!outcome.frame) throw Error(outcome.error);
    return std::move(outcome.frame);
  }
  [[nodiscard]] bool read(std::size_t index) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return asked_ == index && outcome_.has_value();
  }

 private:
  static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  struct Outcome {
    std::optional<Frame> frame;
    std::string error;         // why there is no frame
    double cpu_seconds = 0.0;  // the read's, credited to the thread that takes the frame
  };

  void run() {
    name_this_thread("read " + source_.name());
    // SCHED_IDLE, not only nice 19: a nice-19 thread still runs out its slice (up to 4–5 ms of PNG decoding
    // here) before a woken fusion thread gets the CPU; an idle-policy thread yields at once. Per thread on
    // Linux, allowed without privileges; a failure leaves the thread at nice 19 or the process's priority,
    // which only costs latency.
    (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), 19);
    const sched_param idle{};
    (void)::pthread_setschedparam(::pthread_self(), SCHED_IDLE, &idle);
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      changed_.wait(lock, [&] { return stop_ || (asked_ != kNone && !started_); });
      if (stop_) return;
      started_ = true;
      const std::size_t index = asked_;
      lock.unlock();
      Outcome outcome;
      const double cpu_start = thread_cpu_seconds();
      try {
        outcome.frame = source_.read_recorded(index);
      } catch (const Error& e) {
        outcome.error = e.what();
      }
      outcome.cpu_seconds = thread_cpu_seconds() - cpu_start;
      lock.lock();
      if (asked_ == index && !outcome_) outcome_ = std::move(outcome);
      changed_.notify_all();
    }
  }

  const ReplaySource& source_;  // read_recorded only; entries_ do not change while a reader lives
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t asked_ = kNone;
  bool started_ = false;
  std::optional<Outcome> outcome_;
  bool stop_ = false;
  std::thread thread_;  // last: started once the rest is set up
};

ReplaySource::ReplaySource(ReplayConfig config, SteadyClock& clock)
    : config_(std::move(config)), clock_(clock) {
  if (!(config_.speed > 0) || !std::isfinite(config_.speed)) throw Error("replay: speed must be > 0");
  if (!(config_.rate_hz > 0) || !std::isfinite(config_.rate_hz)) throw Error("replay: rate_hz must be > 0");
}

ReplaySource::~ReplaySource() = default;

bool ReplaySource::next_frame_read() const {
  return reader_ && reader_->read(next_index_);
}

std::string ReplaySource::resolve(const std::string& file) const {
  const std::filesystem::path path(file);
  return path.is_absolute() ? file : (std::filesystem::path(config_.directory) / path).string();
}

SourceStatus ReplaySource::open() {
  ++status_.attempts;
  next_index_ = 0;
  reader_.reset();
  entries_.clear();
  try {
    if (!std::filesystem::is_directory(config_.directory)) {
      throw Error(config_.directory + ": no such replay directory");
    }
    entries_ = read_replay_poses((std::filesystem::path(config_.directory) / "poses.csv").string());
    for (const ReplayEntry& entry : entries_) {
      if (!std::filesystem::is_regular_file(resolve(entry.file)))
        throw Error(resolve(entry.file) + ": no such frame");
    }
  } catch (const Error& e) {
    entries_.clear();
    status_.state = SourceState::kError;
    status_.reason = e.what();
    return status_;
  }
  status_.state = entries_.empty() ? SourceState::kEnded : SourceState::kConnected;
  status_.reason = entries_.empty() ? config_.directory + ": poses.csv lists no frames" : "";
  start_ = config_.start.value_or(clock_.now());
  if (!entries_.empty()) {
    reader_ = std::make_unique<Reader>(*this);
    reader_->ask(0);
  }
  return status_;
}

std::vector<StampedPose> ReplaySource::poses() const {
  std::vector<StampedPose> poses;
  poses.reserve(entries_.size());
  for (const ReplayEntry& entry : entries_) poses.push_back(StampedPose{entry.stamp, entry.X_CE});
  return poses;
}

PinholeIntrinsics ReplaySource::intrinsics_for(const std::string& image_path, int width, int height) const {
  std::string stem = std::filesystem::path(image_path).stem().string();
  const std::string suffix = "_depth";
  if (stem.size() > suffix.size() && stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0) {
    stem.resize(stem.size() - suffix.size());
  }
  const std::filesystem::path xml = std::filesystem::path(image_path).parent_path() / (stem + ".xml");
  const std::filesystem::path yaml = std::filesystem::path(config_.directory) / "intrinsics.yaml";
  PinholeIntrinsics intrinsics;
  if (std::filesystem::is_regular_file(xml)) {
    intrinsics = read_pcl_intrinsics_xml(xml.string());
    intrinsics.width = width;
    intrinsics.height = height;
    intrinsics.max_depth_jump = kDefaultMaxDepthJump;  // PCL's format has no such key
  } else if (std::filesystem::is_regular_file(yaml)) {
    intrinsics = read_intrinsics_yaml(yaml.string());
    if (intrinsics.width != width || intrinsics.height != height) {
      throw Error(image_path + ": image is " + std::to_string(width) + "x" + std::to_string(height) +
                  " but " + yaml.string() + " says " + std::to_string(intrinsics.width) + "x" +
                  std::to_string(intrinsics.height));
    }
  } else {
    throw Error(image_path + ": no intrinsics (neither " + xml.string() + " nor " + yaml.string() + ")");
  }
  return intrinsics;
}

Frame ReplaySource::read_recorded(std::size_t index) const {
  if (index >= entries_.size()) throw Error("replay: frame " + std::to_string(index) + " out of range");
  const ReplayEntry& entry = entries_[index];
  const std::string path = resolve(entry.file);
  Frame frame;
  frame.sensor = config_.name;
  frame.stamp = entry.stamp;
  if (lower_extension(path) == ".pcd") {
    CloudFileOptions options;
    options.require_finite_points = false;  // a frame that saw nothing is still a frame
    frame.points_S = std::move(load_cloud_file(path, options).points);
    return frame;
  }
  RawDepth raw = read_depth_image(path);
  DepthImage image;
  image.intrinsics = intrinsics_for(path, raw.width, raw.height);
  image.depth = std::move(raw.depth);
  frame.depth = std::move(image);
  return frame;
}

void ReplaySource::to_points(Frame& frame) {
  if (frame.depth) frame.points_S = depth_to_points(*frame.depth);
}

Frame ReplaySource::load(std::size_t index) const {
  Frame frame = read_recorded(index);
  to_points(frame);
  return frame;
}

std::optional<Frame> ReplaySource::next(std::chrono::milliseconds timeout) {
  if (status_.state != SourceState::kConnected) return std::nullopt;
  if (next_index_ >= entries_.size()) {
    status_.state = SourceState::kEnded;
    status_.reason = config_.directory + ": end of recording";
    return std::nullopt;
  }
  reader_->ask(next_index_);
  using Duration = SteadyClock::duration;
  SteadyClock::time_point due = clock_.now();
  if (config_.playback == ReplayConfig::Playback::kRecorded) {
    due = start_ + std::chrono::duration_cast<Duration>(std::chrono::duration<double>(
                       (entries_[next_index_].stamp - entries_.front().stamp) / config_.speed));
  } else if (config_.playback == ReplayConfig::Playback::kFixed) {
    due = start_ + std::chrono::duration_cast<Duration>(
                       std::chrono::duration<double>(static_cast<double>(next_index_) / config_.rate_hz));
  }
  if (due > clock_.now() + timeout) {
    clock_.sleep_for(timeout);
    return std::nullopt;
  }
  clock_.sleep_until(due);
  std::optional<Frame> frame;
  try {
    frame = reader_->take(next_index_, timeout);
    if (!frame) return std::nullopt;  // still being read: late
    if (next_index_ + 1 < entries_.size()) reader_->ask(next_index_ + 1);
    to_points(*frame);
  } catch (const Error& e) {
    fail(e.what());
    return std::nullopt;
  }
  ++next_index_;
  ++status_.frames;
  return frame;
}

void ReplaySource::fail(const std::string& reason) {
  status_.state = SourceState::kError;
  status_.reason = reason;
}

void ReplaySource::close() {
  reader_.reset();
  entries_.clear();
  next_index_ = 0;
  status_.state = SourceState::kClosed;
  status_.reason.clear();
}

}  // namespace cellmap
