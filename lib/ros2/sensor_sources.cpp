// SPDX-License-Identifier: Apache-2.0
#include "cellmap/ros2/sensor_sources.hpp"

#include <cstdlib>
#include <deque>
#include <functional>
#include <sstream>
#include <utility>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "cellmap/ros2/laser_scan.hpp"
#include "cellmap/ros2/point_cloud2.hpp"
#include "cellmap/ros2/type_hash.hpp"
#include "quoted.hpp"
#include "wire_views.hpp"

namespace cellmap::ros2 {
namespace {

// Samples the reader keeps for the camera thread: a few frames of any camera or lidar rate.
constexpr std::uint32_t kFrameReaderDepth = 8;

// One ROS 2 sensor topic read as frames. `Message` is the idlc type, `to_frame` reads its body.
template <typename Message>
class TopicSource final : public DepthSource {
 public:
  using ToFrame = std::function<void(const Message& msg, Frame& frame)>;

  TopicSource(const dds::Participant& participant, const dds_topic_descriptor_t* type, const char* type_name,
              std::string name, TopicInput input, transport::OnRefused on_refused, ToFrame to_frame)
      : name_(std::move(name)),
        type_name_(type_name),
        input_(std::move(input)),
        on_refused_(std::move(on_refused)),
        to_frame_(std::move(to_frame)),
        topic_(participant, type, dds_topic(input_.topic)),
        reader_(participant, topic_, reader_qos(input_.reliability, type_name)),
        waitset_(participant) {
    if (input_.frame_id.empty()) throw Error("camera '" + name_ + "': frame_id must not be empty");
    waitset_.attach(reader_);
  }
  ~TopicSource() override {
    try {
      waitset_.detach(reader_);
    } catch (const Error&) {
      // Deleting the reader detaches it anyway.
    }
  }

  [[nodiscard]] const std::string& name() const override { return name_; }

  SourceStatus open() override {
    status_ = {SourceState::kDisconnected, waiting_reason(), 0, 1};
    return status_;
  }

  std::optional<Frame> next(std::chrono::milliseconds timeout) override {
    if (status_.state == SourceState::kClosed) return std::nullopt;
    if (frames_.empty()) {
      waitset_.wait(timeout);
      take();
    }
    update_state();
    if (frames_.empty()) return std::nullopt;
    Frame frame = std::move(frames_.front());
    frames_.pop_front();
    ++status_.frames;
    return frame;
  }

  [[nodiscard]] SourceStatus status() const override { return status_; }
  void close() override {
    status_.state = SourceState::kClosed;
    status_.reason.clear();
    frames_.clear();
  }

 private:
  static dds::Qos reader_qos(Reliability reliability, const char* type_name) {
    dds::Qos qos = dds::Qos::make(false, kFrameReaderDepth);
    if (reliability == Reliability::kBestEffort) qos.best_effort();
    qos.user_data(type_hash_user_data(type_name));
    return qos;
  }

  std::string waiting_reason() const {
    return "no " + std::string(type_name_) + " on " + input_.topic + " yet (" +
           std::to_string(reader_.matched_writers()) + " publishers matched)";
  }

  void take() {
    reader_.take_all([&](const void* sample, const dds_sample_info_t&) {
      try {
        frames_.push_back(to_frame(*static_cast<const Message*>(sample)));
        last_frame_ = steady_seconds();
      } catch (const Error& e) {
        if (on_refused_) on_refused_(input_.topic + " (" + type_name_ + "): " + e.what());
      }
    });
  }

  Frame to_frame(const Message& msg) const {
    const auto& stamp = msg.header.stamp;
    if (stamp.nanosec >= 1'000'000'000u)
      throw Error("header.stamp.nanosec " + std::to_string(stamp.nanosec) + " is not below 1e9");
    const std::int64_t stamp_ns = std::int64_t{stamp.sec} * 1'000'000'000 + stamp.nanosec;
    const std::string frame_id = msg.header.frame_id ? msg.header.frame_id : "";
    if (frame_id != input_.frame_id)
      throw Error("in frame " + quoted(frame_id) + ", not '" + input_.frame_id + "'");
    const std::int64_t skew = stamp_ns - wall_clock_ns();
    if (input_.max_stamp_skew.count() > 0 && std::abs(skew) > input_.max_stamp_skew.count())
      throw Error("stamped " + std::to_string(double(skew) * 1e-9) + " s from now");
    Frame frame;
    frame.sensor = name_;
    frame.stamp = double(stamp_ns) * 1e-9;
    to_frame_(msg, frame);
    return frame;
  }

  void update_state() {
    if (!frames_.empty()) {
      status_.state = SourceState::kConnected;
      status_.reason.clear();
    } else if (status_.state == SourceState::kConnected &&
               steady_seconds() - last_frame_ > input_.frame_timeout) {
      status_.state = SourceState::kDisconnected;
      std::ostringstream reason;
      reason << "no " << type_name_ << " on " << input_.topic << " for " << input_.frame_timeout << " s ("
             << reader_.matched_writers() << " publishers matched)";
      status_.reason = reason.str();
    } else if (status_.state == SourceState::kDisconnected) {
      status_.reason = status_.frames == 0 ? waiting_reason() : status_.reason;
    }
  }

  std::string name_;
  const char* type_name_;
  TopicInput input_;
  transport::OnRefused on_refused_;
  ToFrame to_frame_;
  dds::Topic topic_;
  dds::Reader reader_;
  dds::WaitSet waitset_;
  std::deque<Frame> frames_;
  SourceStatus status_;
  double last_frame_ = 0.0;
};

}  // namespace

std::unique_ptr<DepthSource> make_point_cloud2_source(const dds::Participant& participant, std::string name,
                                                      TopicInput input, transport::OnRefused on_refused) {
  using Message = sensor_msgs_msg_dds__PointCloud2_;
  const auto min_range = float(input.min_range);
  return std::make_unique<TopicSource<Message>>(
      participant, &sensor_msgs_msg_dds__PointCloud2__desc, "sensor_msgs/msg/PointCloud2", std::move(name),
      std::move(input), std::move(on_refused),
      [min_range](const Message& msg, Frame& frame) { frame.points_S = to_points(view_of(msg), min_range); });
}

std::unique_ptr<DepthSource> make_laser_scan_source(const dds::Participant& participant, std::string name,
                                                    TopicInput input, transport::OnRefused on_refused) {
  using Message = sensor_msgs_msg_dds__LaserScan_;
  return std::make_unique<TopicSource<Message>>(
      participant, &sensor_msgs_msg_dds__LaserScan__desc, "sensor_msgs/msg/LaserScan", std::move(name),
      std::move(input), std::move(on_refused), [](const Message& msg, Frame& frame) {
        ScanPoints scan = to_points(view_of(msg));
        frame.points_S = std::move(scan.points_S);
        frame.no_return_S = std::move(scan.no_return_S);
        frame.field_of_view = std::move(scan.fan);
      });
}

}  // namespace cellmap::ros2
