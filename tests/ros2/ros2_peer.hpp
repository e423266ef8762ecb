// SPDX-License-Identifier: Apache-2.0
#pragma once
// The ROS 2 node of the end-to-end tests: tests/ros2/peer's Fast DDS program (another DDS vendor, ROS 2's
// default one) as a child process, told what to publish on its stdin, its JSON lines read on a thread of
// their own so that it never blocks on a full pipe. The messages a test hands it are built here from
// cellmap's values (a rendered frame's points, a scan's ranges, joint positions) exactly as ROS 2 drivers
// lay them out.

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cellmap/frame/cloud.hpp"
#include "support/test_support.hpp"
#include "transport/child_process.hpp"

namespace cellmap::test {

class Ros2Peer {
 public:
  /// Starts the peer on `domain` and waits until it says it is ready.
  explicit Ros2Peer(int domain)
      : process_({ROS2_PEER, "--domain", std::to_string(domain)}, ChildProcess::Input::from_test),
        reader_([this] { read_lines(); }) {
    const auto ready = [this] {
      const std::vector<nlohmann::json> all = events();
      return std::any_of(all.begin(), all.end(),
                         [](const nlohmann::json& e) { return e.value("event", "") == "ready"; });
    };
    if (!wait_until(ready)) ADD_FAILURE() << "the ROS 2 peer did not start";
  }
  ~Ros2Peer() {
    process_.close_input();
    process_.signal(SIGTERM);
    reader_.join();
  }
  Ros2Peer(const Ros2Peer&) = delete;
  Ros2Peer& operator=(const Ros2Peer&) = delete;

  /// One command line (key=value words); `bytes` follow it when given (the command must then end with
  /// "bytes=N", which this adds).
  void command(const std::string& line, const std::string& bytes = "") {
    const std::lock_guard<std::mutex> lock(write_mutex_);
    process_.write_input(line + (bytes.empty() ? "" : " bytes=" + std::to_string(bytes.size())) + "\n" +
                         bytes);
  }

  /// A reader of `topic` with MoveIt's QoS for collision objects (RELIABLE, VOLATILE, KEEP_LAST 1024) or
  /// RViz's for markers (RELIABLE, TRANSIENT_LOCAL).
  void subscribe(const std::string& topic, const std::string& type, bool transient_local, int depth) {
    command("sub topic=" + topic + " type=" + type + " reliability=reliable durability=" +
            (transient_local ? "transient_local" : "volatile") + " depth=" + std::to_string(depth));
  }

  /// An organized cloud of `width` × `height` points (NaN where a pixel has no return) as an RGB-D driver
  /// sends it: x, y, z FLOAT32 at 0, 4, 8, a FLOAT32 rgb at 16, point_step 32 (PCL's PointXYZRGB layout).
  void publish_cloud(const std::string& topic, const std::string& frame, std::uint32_t width,
                     std::uint32_t height, const std::vector<Eigen::Vector3f>& points,
                     std::int64_t stamp_ns = 0) {
    std::string data(std::size_t(width) * height * 32, '\0');
    for (std::size_t i = 0; i < points.size() && i < std::size_t(width) * height; ++i)
      std::memcpy(data.data() + 32 * i, points[i].data(), 12);
    command("pub-cloud topic=" + topic + " frame=" + frame + stamp(stamp_ns) +
                " height=" + std::to_string(height) + " width=" + std::to_string(width) +
                " point_step=32 row_step=" + std::to_string(32 * width) +
                " bigendian=0 dense=0 fields=x:0:7:1,y:4:7:1,z:8:7:1,rgb:16:7:1 reliability=best_effort",
            data);
  }

  void publish_scan(const std::string& topic, const std::string& frame, float angle_min,
                    float angle_increment, float range_min, float range_max, const std::vector<float>& ranges,
                    std::int64_t stamp_ns) {
    std::string data(ranges.size() * 4, '\0');
    std::memcpy(data.data(), ranges.data(), data.size());
    const float angle_max = angle_min + angle_increment * float(ranges.size() - 1);
    command("pub-scan topic=" + topic + " frame=" + frame + stamp(stamp_ns) +
                " angle_min=" + number(angle_min) + " angle_max=" + number(angle_max) + " angle_increment=" +
                number(angle_increment) + " time_increment=0 scan_time=0 range_min=" + number(range_min) +
                " range_max=" + number(range_max) + " reliability=best_effort",
            data);
  }

  void publish_joints(const std::string& topic, const std::vector<std::string>& names,
                      const std::vector<double>& positions, std::int64_t stamp_ns) {
    std::string n, p;
    for (std::size_t i = 0; i < names.size(); ++i) {
      n += (i ? "," : "") + names[i];
      p += (i ? "," : "") + number(positions[i]);
    }
    command("pub-joints topic=" + topic + stamp(stamp_ns) + " names=" + n + " positions=" + p);
  }

  /// Every event so far, in order.
  [[nodiscard]] std::vector<nlohmann::json> events() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return events_;
  }
  /// The messages received on `topic` so far, from event index `from` on.
  [[nodiscard]] std::vector<nlohmann::json> received(const std::string& topic, std::size_t from = 0) const {
    std::vector<nlohmann::json> out;
    const std::vector<nlohmann::json> all = events();
    for (std::size_t i = from; i < all.size(); ++i) {
      if (all[i].value("event", "") == "received" && all[i].value("topic", "") == topic)
        out.push_back(all[i]["msg"]);
    }
    return out;
  }
  [[nodiscard]] std::size_t event_count() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return events_.size();
  }
  /// Waits until `done()` (called without the peer's lock, so it may look at events()) is true; false after
  /// `patience`. Checks again whenever an event comes, and every 100 ms.
  bool wait_until(const std::function<bool()>& done, std::chrono::seconds patience = kPatience) const {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    for (;;) {
      std::size_t seen = event_count();
      if (done()) return true;
      if (std::chrono::steady_clock::now() >= deadline) return false;
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait_until(
          lock, std::min(deadline, std::chrono::steady_clock::now() + std::chrono::milliseconds(100)),
          [&] { return events_.size() != seen; });
    }
  }

 private:
  static std::string stamp(std::int64_t ns) { return ns > 0 ? " stamp=" + std::to_string(ns) : ""; }
  static std::string number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", value);
    return text;
  }

  void read_lines() {
    while (std::optional<std::string> line = process_.read_line(std::chrono::seconds(3600))) {
      nlohmann::json event = nlohmann::json::parse(*line, nullptr, false);
      if (event.is_discarded()) continue;
      const std::lock_guard<std::mutex> lock(mutex_);
      events_.push_back(std::move(event));
      changed_.notify_all();
    }
  }

  ChildProcess process_;
  std::mutex write_mutex_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::vector<nlohmann::json> events_;
  std::thread reader_;
};

}  // namespace cellmap::test
