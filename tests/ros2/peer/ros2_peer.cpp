// SPDX-License-Identifier: Apache-2.0
// ros2_peer --domain N: a stand-in ROS 2 node on eProsima Fast DDS 2.9, driven by commands on stdin, one per
// line; it prints JSON lines on stdout (tests/ros2/peer/README.md has the protocol) and diagnostics on
// stderr. Tests use it to check that cellmap (Cyclone DDS) meets ROS 2 nodes on the wire.

#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/log/StdoutErrConsumer.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include <time.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "command.hpp"
#include "input.hpp"
#include "message_json.hpp"
#include "moveit_msgs/msg/CollisionObjectPubSubTypes.h"
#include "node.hpp"
#include "sensor_msgs/msg/JointStatePubSubTypes.h"
#include "sensor_msgs/msg/LaserScanPubSubTypes.h"
#include "sensor_msgs/msg/PointCloud2PubSubTypes.h"
#include "visualization_msgs/msg/MarkerArrayPubSubTypes.h"

namespace ros2_peer {
namespace {

namespace dds = eprosima::fastdds::dds;
using builtin_interfaces::msg::dds_::Time_;
using eprosima::fastrtps::types::ReturnCode_t;
using namespace std::chrono_literals;

const RosType kPointCloud2{"sensor_msgs/msg/PointCloud2",
                           [] { return new sensor_msgs::msg::dds_::PointCloud2_PubSubType(); }};
const RosType kLaserScan{"sensor_msgs/msg/LaserScan",
                         [] { return new sensor_msgs::msg::dds_::LaserScan_PubSubType(); }};
const RosType kJointState{"sensor_msgs/msg/JointState",
                          [] { return new sensor_msgs::msg::dds_::JointState_PubSubType(); }};
const RosType kCollisionObject{"moveit_msgs/msg/CollisionObject",
                               [] { return new moveit_msgs::msg::dds_::CollisionObject_PubSubType(); }};
const RosType kMarkerArray{"visualization_msgs/msg/MarkerArray",
                           [] { return new visualization_msgs::msg::dds_::MarkerArray_PubSubType(); }};

const std::vector<std::string> kQosWords = {"reliability", "durability", "depth"};
// Words every publish command takes besides its own.
const std::vector<std::string> kPublishWords = {"topic", "stamp",  "reliability", "durability",
                                                "depth", "repeat", "rate"};

std::vector<std::string> operator+(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

/// {"event":NAME,...}: the caller adds members, then print() closes and prints it.
Json event(const char* name) {
  Json json;
  json.begin_object().key("event").text(name);
  return json;
}

void print(Json& json) {
  json.end_object();
  print_line(json.str());
}

/// The stamp= of a command (integer nanoseconds since the Unix epoch) as ROS Time.
Time_ to_time(std::int64_t nanoseconds) {
  // Floor division: nanosec stays in [0, 1e9) for times before 1970 too.
  std::int64_t seconds = nanoseconds / 1'000'000'000;
  std::int64_t rest = nanoseconds % 1'000'000'000;
  if (rest < 0) {
    rest += 1'000'000'000;
    --seconds;
  }
  if (seconds < INT32_MIN || seconds > INT32_MAX)
    throw CommandError("stamp: seconds beyond ROS Time's int32");
  Time_ time;
  time.sec(static_cast<std::int32_t>(seconds));
  time.nanosec(static_cast<std::uint32_t>(rest));
  return time;
}

Time_ now() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return to_time(static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec);
}

QosSpec qos_of(const Command& command) {
  QosSpec qos;
  if (command.has("reliability")) {
    const std::string& value = command.text("reliability");
    if (value != "reliable" && value != "best_effort")
      throw CommandError("reliability: reliable or best_effort");
    qos.reliable = value == "reliable";
  }
  if (command.has("durability")) {
    const std::string& value = command.text("durability");
    if (value != "volatile" && value != "transient_local") {
      throw CommandError("durability: volatile or transient_local");
    }
    qos.transient_local = value == "transient_local";
  }
  if (command.has("depth")) {
    const std::uint32_t depth = command.uint32("depth");
    if (depth < 1 || depth > INT32_MAX) throw CommandError("depth: at least 1");
    qos.depth = static_cast<std::int32_t>(depth);
  }
  return qos;
}

bool qos_given(const Command& command) {
  for (const std::string& word : kQosWords) {
    if (command.has(word)) return true;
  }
  return false;
}

/// `bytes` as little-endian float32 (what the tests send, whatever this host is).
std::vector<float> little_endian_floats(const std::vector<std::uint8_t>& bytes) {
  std::vector<float> values(bytes.size() / 4);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::uint8_t* b = &bytes[4 * i];
    const std::uint32_t bits = static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
                               static_cast<std::uint32_t>(b[2]) << 16 |
                               static_cast<std::uint32_t>(b[3]) << 24;
    std::memcpy(&values[i], &bits, sizeof bits);
  }
  return values;
}

/// Prints each valid sample `reader` holds as {"event":"received",...} with the whole message.
template <typename Msg>
std::function<void(dds::DataReader&)> printer(const std::string& topic, const std::string& type) {
  return [topic, type](dds::DataReader& reader) {
    Msg message;
    dds::SampleInfo info;
    while (reader.take_next_sample(&message, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;  // a writer gone or an instance disposed: no message
      Json json = event("received");
      json.key("topic").text(topic).key("type").text(type).key("msg");
      write(json, message);
      print(json);
    }
  };
}

class Peer final {
 public:
  Peer(Node& node, Signals& signals, Input& input) : node_(node), signals_(signals), input_(input) {}

  /// Runs one command line; a bad one prints {"event":"error",...}. A payload (bytes=N) is read first, so
  /// the input stays in step even when the command is refused.
  void run(const std::string& line) {
    std::vector<std::uint8_t> payload;
    try {
      std::optional<Command> command;
      try {
        command = Command::parse(line);
      } catch (const CommandError&) {
        skip_payload(line);
        throw;
      }
      if (command->has("bytes")) {
        const auto count = parse_number<std::uint64_t>(command->text("bytes"), "bytes");
        if (!input_.bytes(count, payload)) throw CommandError("input ended inside the payload");
      }
      dispatch(*command, std::move(payload));
    } catch (const std::exception& error) {
      Json json = event("error");
      json.key("reason").text(error.what());
      print(json);
    }
  }

 private:
  void dispatch(const Command& command, std::vector<std::uint8_t> payload) {
    const std::string& verb = command.verb();
    if (verb == "pub-cloud") return pub_cloud(command, std::move(payload));
    if (verb == "pub-scan") return pub_scan(command, payload);
    if (verb == "pub-joints") return pub_joints(command);
    if (verb == "advertise") return advertise(command);
    if (verb == "sub") return sub(command);
    if (verb == "unsub") return unsub(command);
    if (verb == "wait-match") return wait_match(command);
    if (verb == "sleep") return sleep(command);
    throw CommandError("unknown command '" + verb + "'");
  }

  // A line that does not parse may still announce a payload: read it, or its bytes would be taken for
  // commands.
  void skip_payload(const std::string& line) {
    const auto at = line.find("bytes=");
    if (at == std::string::npos || (at > 0 && line[at - 1] != ' ' && line[at - 1] != '\t')) return;
    const std::string value = line.substr(at + 6, line.find_first_of(" \t", at) - at - 6);
    try {
      std::vector<std::uint8_t> ignored;
      input_.bytes(parse_number<std::uint64_t>(value, "bytes"), ignored);
    } catch (const CommandError&) {
      // No count to trust: the payload's bytes will come as lines and be refused.
    }
  }

  void pub_cloud(const Command& command, std::vector<std::uint8_t> payload) {
    command.allow_only(kPublishWords + std::vector<std::string>{"frame", "height", "width", "point_step",
                                                                "row_step", "bigendian", "dense", "fields",
                                                                "bytes"});
    sensor_msgs::msg::dds_::PointCloud2_ cloud;
    cloud.header().frame_id(command.text("frame"));
    cloud.height(command.uint32("height"));
    cloud.width(command.uint32("width"));
    for (const FieldSpec& spec : command.fields("fields")) {
      sensor_msgs::msg::dds_::PointField_ field;
      field.name(spec.name);
      field.offset(spec.offset);
      field.datatype(spec.datatype);
      field.count(spec.count);
      cloud.fields().push_back(field);
    }
    cloud.is_bigendian(command.flag("bigendian"));
    cloud.point_step(command.uint32("point_step"));
    cloud.row_step(command.uint32("row_step"));
    cloud.is_dense(command.flag("dense"));
    // No check of the layout against the data: tests send malformed clouds on purpose.
    cloud.data(std::move(payload));
    publish(command, kPointCloud2, cloud);
  }

  void pub_scan(const Command& command, const std::vector<std::uint8_t>& payload) {
    command.allow_only(kPublishWords + std::vector<std::string>{
                                           "frame", "angle_min", "angle_max", "angle_increment",
                                           "time_increment", "scan_time", "range_min", "range_max", "bytes"});
    if (!command.has("bytes")) throw CommandError("pub-scan needs bytes= (the ranges, float32 each)");
    if (payload.size() % 4 != 0) throw CommandError("pub-scan: bytes= is not a multiple of 4");
    sensor_msgs::msg::dds_::LaserScan_ scan;
    scan.header().frame_id(command.text("frame"));
    scan.angle_min(command.float32("angle_min"));
    scan.angle_max(command.float32("angle_max"));
    scan.angle_increment(command.float32("angle_increment"));
    scan.time_increment(command.float32("time_increment"));
    scan.scan_time(command.float32("scan_time"));
    scan.range_min(command.float32("range_min"));
    scan.range_max(command.float32("range_max"));
    scan.ranges(little_endian_floats(payload));
    publish(command, kLaserScan, scan);
  }

  void pub_joints(const Command& command) {
    command.allow_only(kPublishWords + std::vector<std::string>{"frame", "names", "positions"});
    sensor_msgs::msg::dds_::JointState_ joints;
    joints.header().frame_id(command.text_or("frame", ""));
    // Counts may differ on purpose: a test of what cellmapd does with a malformed joint state.
    joints.name(command.list("names"));
    joints.position(command.float64_list("positions"));
    publish(command, kJointState, joints);
  }

  /// Writes `message` once, or repeat=K times at rate=HZ (as fast as it goes without rate=), each time with
  /// the command's stamp or the time of that write.
  template <typename Msg>
  void publish(const Command& command, const RosType& type, Msg& message) {
    const std::string& topic = command.text("topic");
    const std::optional<Time_> stamp =
        command.has("stamp") ? std::optional<Time_>(to_time(command.int64("stamp"))) : std::nullopt;
    const std::uint64_t repeat =
        command.has("repeat") ? parse_number<std::uint64_t>(command.text("repeat"), "repeat") : 1;
    const double rate = command.has("rate") ? command.float64("rate") : 0.0;
    if (repeat < 1) throw CommandError("repeat: at least 1");
    if (!(rate >= 0.0)) throw CommandError("rate: not negative");
    dds::DataWriter& writer = node_.writer(topic, type, qos_of(command), qos_given(command));

    const auto start = std::chrono::steady_clock::now();
    auto last_write = start;
    std::uint64_t written = 0;
    for (std::uint64_t i = 0; i < repeat; ++i) {
      if (rate > 0.0) {
        // On a fixed schedule from the first write, so a late wake-up does not slow the rest.
        const auto due = start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     std::chrono::duration<double>(static_cast<double>(i) / rate));
        if (!signals_.sleep_for(due - std::chrono::steady_clock::now())) break;
      } else if (signals_.raised()) {
        break;
      }
      last_write = std::chrono::steady_clock::now();
      message.header().stamp(stamp ? *stamp : now());
      if (!writer.write(&message)) throw std::runtime_error("Fast DDS refused the write on " + topic);
      ++written;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    Json json = event("published");
    json.key("topic").text(topic).key("count").integer(
        static_cast<std::int64_t>(node_.count_written(topic, written)));
    if (command.has("repeat")) {
      const double sample_bytes = static_cast<double>(Msg::getCdrSerializedSize(message));
      json.key("repeat").integer(static_cast<std::int64_t>(written));
      json.key("seconds").real(seconds);
      // Writes per second between the first and the last one (the last write's own time is not an interval).
      const double span = std::chrono::duration<double>(last_write - start).count();
      json.key("rate_hz").real(written > 1 ? static_cast<double>(written - 1) / span : 0.0);
      json.key("sample_bytes").real(sample_bytes);
      json.key("megabytes_per_s").real(static_cast<double>(written) * sample_bytes / seconds / 1e6);
    }
    print(json);
  }

  // A writer before the first sample, as a ROS node creates its publishers at start: a test waits for the
  // match (wait-match) so the first sample is not lost on a VOLATILE topic.
  void advertise(const Command& command) {
    command.allow_only(kQosWords + std::vector<std::string>{"topic", "type"});
    const std::string& topic = command.text("topic");
    const std::string& type = command.text("type");
    const RosType* known = nullptr;
    for (const RosType* candidate : {&kPointCloud2, &kLaserScan, &kJointState}) {
      if (candidate->name == type) known = candidate;
    }
    if (known == nullptr) {
      throw CommandError("advertise: type " + type + " is not one the peer publishes (" + kPointCloud2.name +
                         ", " + kLaserScan.name + ", " + kJointState.name + ")");
    }
    node_.writer(topic, *known, qos_of(command), qos_given(command));
    Json json = event("advertised");
    json.key("topic").text(topic);
    print(json);
  }

  void sub(const Command& command) {
    command.allow_only(kQosWords + std::vector<std::string>{"topic", "type"});
    const std::string& topic = command.text("topic");
    const std::string& type = command.text("type");
    if (type == kCollisionObject.name) {
      node_.subscribe(topic, kCollisionObject, qos_of(command),
                      printer<moveit_msgs::msg::dds_::CollisionObject_>(topic, type));
    } else if (type == kMarkerArray.name) {
      node_.subscribe(topic, kMarkerArray, qos_of(command),
                      printer<visualization_msgs::msg::dds_::MarkerArray_>(topic, type));
    } else {
      throw CommandError("sub: type " + type + " is not one the peer reads (" + kCollisionObject.name + ", " +
                         kMarkerArray.name + ")");
    }
    Json json = event("subscribed");
    json.key("topic").text(topic);
    print(json);
  }

  void unsub(const Command& command) {
    command.allow_only({"topic"});
    node_.unsubscribe(command.text("topic"));
    Json json = event("unsubscribed");
    json.key("topic").text(command.text("topic"));
    print(json);
  }

  void wait_match(const Command& command) {
    command.allow_only({"topic", "count", "timeout"});
    const std::string& topic = command.text("topic");
    const std::uint32_t wanted = command.uint32("count");
    const double timeout = command.has("timeout") ? command.float64("timeout") : 10.0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
    // count=0 waits for the last match to go; count=N for at least N.
    const auto done = [&](int matched) {
      return wanted == 0 ? matched == 0 : matched >= static_cast<std::int64_t>(wanted);
    };
    int matched = node_.matched(topic);
    while (!done(matched) && std::chrono::steady_clock::now() < deadline && signals_.sleep_for(20ms)) {
      matched = node_.matched(topic);
    }
    Json json = event(done(matched) ? "matched" : "timeout");
    json.key("topic").text(topic).key("count").integer(matched);
    print(json);
  }

  void sleep(const Command& command) {
    command.allow_only({"seconds"});
    const double seconds = command.float64("seconds");
    if (!(seconds >= 0.0)) throw CommandError("seconds: not negative");
    signals_.sleep_for(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(seconds)));
  }

  Node& node_;
  Signals& signals_;
  Input& input_;
};

int usage(const char* reason) {
  std::cerr << "ros2_peer: " << reason << "\nusage: ros2_peer --domain N   (commands on stdin)\n";
  return 2;
}

}  // namespace
}  // namespace ros2_peer

int main(int argc, char** argv) {
  using namespace ros2_peer;
  std::uint32_t domain = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--domain" && i + 1 < argc) {
      try {
        domain = parse_number<std::uint32_t>(argv[++i], "--domain");
      } catch (const CommandError& error) {
        return usage(error.what());
      }
    } else {
      return usage(("unknown argument " + arg).c_str());
    }
  }

  // Fast DDS logs to stdout by default, where it would break the JSON lines.
  namespace dds = eprosima::fastdds::dds;
  dds::Log::ClearConsumers();
  auto to_stderr = std::make_unique<dds::StdoutErrConsumer>();
  to_stderr->stderr_threshold(dds::Log::Kind::Info);
  dds::Log::RegisterConsumer(std::move(to_stderr));
  dds::Log::SetVerbosity(dds::Log::Kind::Warning);

  try {
    Signals signals;  // before the participant: Fast DDS's threads inherit the blocked signals
    Node node(domain);
    Json ready = event("ready");
    ready.key("domain").integer(domain);
    print(ready);

    Input input(signals);
    Peer peer(node, signals, input);
    while (const std::optional<std::string> line = input.line()) {
      if (line->find_first_not_of(" \t\r") == std::string::npos) continue;
      peer.run(*line);
      if (signals.raised()) break;
    }
    // At the end of the input (not on a signal) give reliable readers the chance to get the last samples.
    if (!signals.raised()) node.wait_for_acknowledgments(2s);
  } catch (const std::exception& error) {
    std::cerr << "ros2_peer: " << error.what() << "\n";
    return 1;
  }
  dds::Log::Flush();
  return 0;
}
