// SPDX-License-Identifier: Apache-2.0
#pragma once
// The stand-in ROS 2 node on Fast DDS 2.9: one participant on 127.0.0.1 only, and writers and readers that
// follow ROS 2's wire conventions (rmw_fastrtps and rmw_cyclonedds agree on them):
//   topic /a/b          -> DDS topic "rt/a/b"
//   type pkg/msg/T      -> DDS type "pkg::msg::dds_::T_" (the IDL of idl/ros2), plain CDR (XCDR1)
//   QoS                 -> RELIABLE, VOLATILE, KEEP_LAST 10 unless a command says otherwise; default
//   partition.

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace ros2_peer {

/// The QoS a command asks for (reliability=, durability=, depth=), ROS 2's default where it says nothing.
struct QosSpec {
  bool reliable = true;
  bool transient_local = false;
  std::int32_t depth = 10;
  bool operator==(const QosSpec& other) const {
    return reliable == other.reliable && transient_local == other.transient_local && depth == other.depth;
  }
};

/// A ROS 2 message type the peer knows: its ROS name and the fastddsgen type support.
struct RosType {
  std::string name;  // pkg/msg/T
  std::function<eprosima::fastdds::dds::TopicDataType*()> make_support;
};

/// "/a/b" (or "a/b") -> "rt/a/b". @throws std::invalid_argument for an empty name.
std::string dds_topic_name(const std::string& ros_topic);
/// "pkg/msg/T" -> "pkg::msg::dds_::T_". @throws std::invalid_argument if it is not of that form.
std::string dds_type_name(const std::string& ros_type);

class Node final {
 public:
  /// Joins `domain` over UDPv4 on 127.0.0.1 only (no shared memory, no multicast), finding Cyclone DDS
  /// participants there by unicast (tests/transport/loopback.hpp). @throws std::runtime_error if Fast DDS
  /// refuses.
  explicit Node(std::uint32_t domain);
  /// Deletes every writer and reader, then the participant.
  ~Node();
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  /// The writer of `ros_topic`, created with `qos` on first use. @throws std::runtime_error if the topic
  /// has another type, or `qos_given` and the existing writer has another QoS.
  eprosima::fastdds::dds::DataWriter& writer(const std::string& ros_topic, const RosType& type,
                                             const QosSpec& qos, bool qos_given);
  /// Creates a reader of `ros_topic`; Fast DDS calls `on_data` (on a thread of its own) whenever it holds
  /// samples. @throws std::runtime_error if the topic already has a reader here or has another type.
  void subscribe(const std::string& ros_topic, const RosType& type, const QosSpec& qos,
                 std::function<void(eprosima::fastdds::dds::DataReader&)> on_data);
  /// Deletes the reader of `ros_topic`. @throws std::runtime_error if there is none.
  void unsubscribe(const std::string& ros_topic);

  /// How many remote readers the writer of `ros_topic` matches now or, without a writer here, how many
  /// remote writers its reader matches. @throws std::runtime_error if the topic has neither.
  [[nodiscard]] int matched(const std::string& ros_topic) const;
  /// Counts `samples` more written on `ros_topic`; returns how many were written on it so far.
  std::uint64_t count_written(const std::string& ros_topic, std::uint64_t samples) {
    return written_[dds_topic_name(ros_topic)] += samples;
  }
  /// Waits until every matched reader acknowledged the reliable writers' samples, or `timeout` passed.
  void wait_for_acknowledgments(std::chrono::nanoseconds timeout);

 private:
  eprosima::fastdds::dds::Topic& topic(const std::string& ros_topic, const RosType& type);

  struct Writer {
    eprosima::fastdds::dds::DataWriter* writer;
    QosSpec qos;
  };
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  // All by DDS topic name: "/a" and "a" are one topic.
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  std::set<std::string> registered_types_;
  std::map<std::string, Writer> writers_;
  std::map<std::string, eprosima::fastdds::dds::DataReader*> readers_;
  std::map<std::string, std::uint64_t> written_;
  // Kept until the node ends: Fast DDS may still be inside a callback of a reader being deleted.
  std::vector<std::unique_ptr<eprosima::fastdds::dds::DataReaderListener>> listeners_;
  std::unique_ptr<eprosima::fastdds::dds::DataWriterListener> writer_listener_;
};

}  // namespace ros2_peer
