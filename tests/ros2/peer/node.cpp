// SPDX-License-Identifier: Apache-2.0
#include "node.hpp"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>

#include <iostream>
#include <stdexcept>

namespace ros2_peer {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::Duration_t;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;
using eprosima::fastrtps::types::ReturnCode_t;

namespace {

// Cyclone probes participant indices 0..30 on 127.0.0.1 (MaxAutoParticipantIndex of loopback.hpp); Fast DDS
// probes this many from 0 the same way (both take RTPS's well-known ports, 7400 + 250 d + 10 + 2 i).
constexpr std::uint32_t kProbedParticipants = 32;
// A 640x480 cloud is ~5 MB, ~80 datagrams of 64 kB sent at once: the default 208 kB socket buffers drop most
// of them and the repairs take seconds. Linux caps this at net.core.{w,r}mem_max (4 MB on our machines).
constexpr std::uint32_t kSocketBuffer = 8 * 1024 * 1024;
// Fast DDS's default heartbeat is 3 s: a lost fragment of a big cloud would wait that long for its repair.
const Duration_t kHeartbeatPeriod(0, 100'000'000);

Duration_t to_duration(std::chrono::nanoseconds time) {
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(time);
  return Duration_t(static_cast<std::int32_t>(seconds.count()),
                    static_cast<std::uint32_t>((time - seconds).count()));
}

const char* plural(int count) {
  return count == 1 ? "" : "s";
}

class WriterListener final : public dds::DataWriterListener {
 public:
  void on_publication_matched(dds::DataWriter* writer, const dds::PublicationMatchedStatus& status) override {
    std::cerr << "ros2_peer: writer of " << writer->get_topic()->get_name() << " matches "
              << status.current_count << " reader" << plural(status.current_count) << "\n";
  }
  void on_offered_incompatible_qos(dds::DataWriter* writer,
                                   const dds::OfferedIncompatibleQosStatus& status) override {
    std::cerr << "ros2_peer: writer of " << writer->get_topic()->get_name()
              << " met a reader with incompatible QoS (policy id " << status.last_policy_id << ")\n";
  }
};

class ReaderListener final : public dds::DataReaderListener {
 public:
  explicit ReaderListener(std::function<void(dds::DataReader&)> on_data) : on_data_(std::move(on_data)) {}
  void on_data_available(dds::DataReader* reader) override { on_data_(*reader); }
  void on_subscription_matched(dds::DataReader* reader,
                               const dds::SubscriptionMatchedStatus& status) override {
    std::cerr << "ros2_peer: reader of " << reader->get_topicdescription()->get_name() << " matches "
              << status.current_count << " writer" << plural(status.current_count) << "\n";
  }
  void on_requested_incompatible_qos(dds::DataReader* reader,
                                     const dds::RequestedIncompatibleQosStatus& status) override {
    std::cerr << "ros2_peer: reader of " << reader->get_topicdescription()->get_name()
              << " met a writer with incompatible QoS (policy id " << status.last_policy_id << ")\n";
  }

 private:
  std::function<void(dds::DataReader&)> on_data_;
};

void check(const ReturnCode_t& rc, const std::string& what) {
  if (rc != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error(what + " failed (Fast DDS return code " + std::to_string(rc()) + ")");
  }
}

Locator_t loopback() {
  Locator_t locator;  // UDPv4, port 0: Fast DDS fills in the well-known ports
  IPLocator::setIPv4(locator, 127, 0, 0, 1);
  return locator;
}

}  // namespace

std::string dds_topic_name(const std::string& ros_topic) {
  const std::string name = !ros_topic.empty() && ros_topic.front() == '/' ? ros_topic.substr(1) : ros_topic;
  if (name.empty()) throw std::invalid_argument("empty topic name");
  return "rt/" + name;
}

std::string dds_type_name(const std::string& ros_type) {
  const auto first = ros_type.find('/');
  const auto last = ros_type.rfind('/');
  if (first == std::string::npos || first == last || first == 0 || last + 1 == ros_type.size()) {
    throw std::invalid_argument("'" + ros_type + "' is not pkg/msg/Type");
  }
  const std::string package = ros_type.substr(0, first);
  const std::string kind = ros_type.substr(first + 1, last - first - 1);
  return package + "::" + kind + "::dds_::" + ros_type.substr(last + 1) + "_";
}

Node::Node(std::uint32_t domain) : writer_listener_(std::make_unique<WriterListener>()) {
  dds::DomainParticipantQos qos = dds::PARTICIPANT_QOS_DEFAULT;
  qos.name("ros2_peer");
  // UDPv4 on 127.0.0.1 only. Without the whitelist Fast DDS announces the machine's external address
  // only, where a Cyclone pinned to 127.0.0.1 never answers; the builtin transports would add shared
  // memory, which Cyclone does not speak.
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.push_back("127.0.0.1");
  udp->maxInitialPeersRange = kProbedParticipants;
  udp->sendBufferSize = kSocketBuffer;
  udp->receiveBufferSize = kSocketBuffer;
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports.push_back(udp);
  // Discovery by unicast to 127.0.0.1 (lo has no multicast). Naming the unicast locators also keeps Fast DDS
  // from announcing its default multicast ones.
  qos.wire_protocol().builtin.initialPeersList.push_back(loopback());
  qos.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(loopback());
  qos.wire_protocol().default_unicast_locator_list.push_back(loopback());

  participant_ = dds::DomainParticipantFactory::get_instance()->create_participant(domain, qos);
  if (participant_ == nullptr) throw std::runtime_error("cannot join DDS domain " + std::to_string(domain));
  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr) {
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    throw std::runtime_error("cannot create a publisher and a subscriber");
  }
}

Node::~Node() {
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

dds::Topic& Node::topic(const std::string& ros_topic, const RosType& type) {
  const std::string dds_type = dds_type_name(type.name);
  const auto found = topics_.find(dds_topic_name(ros_topic));
  if (found != topics_.end()) {
    if (found->second->get_type_name() != dds_type) {
      throw std::runtime_error(ros_topic + " has type " + found->second->get_type_name() + ", not " +
                               dds_type);
    }
    return *found->second;
  }
  if (registered_types_.count(dds_type) == 0) {
    dds::TypeSupport support(type.make_support());
    // The IDL's names must follow ROS's rule, or no ROS node would match: checked here, where both meet.
    if (support.get_type_name() != dds_type) {
      throw std::runtime_error("the IDL names " + type.name + " " + support.get_type_name() + ", ROS 2 " +
                               dds_type);
    }
    check(support.register_type(participant_), "registering " + dds_type);
    registered_types_.insert(dds_type);
  }
  dds::Topic* created =
      participant_->create_topic(dds_topic_name(ros_topic), dds_type, dds::TOPIC_QOS_DEFAULT);
  if (created == nullptr) throw std::runtime_error("cannot create topic " + dds_topic_name(ros_topic));
  topics_.emplace(dds_topic_name(ros_topic), created);
  return *created;
}

dds::DataWriter& Node::writer(const std::string& ros_topic, const RosType& type, const QosSpec& qos,
                              bool qos_given) {
  const auto found = writers_.find(dds_topic_name(ros_topic));
  if (found != writers_.end()) {
    dds::Topic* existing = found->second.writer->get_topic();
    if (existing->get_type_name() != dds_type_name(type.name)) {
      throw std::runtime_error(ros_topic + " has type " + existing->get_type_name());
    }
    if (qos_given && !(found->second.qos == qos)) {
      throw std::runtime_error("the writer of " + ros_topic + " exists with another QoS");
    }
    return *found->second.writer;
  }
  dds::DataWriterQos writer_qos = dds::DATAWRITER_QOS_DEFAULT;
  writer_qos.reliability().kind =
      qos.reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  writer_qos.durability().kind =
      qos.transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  writer_qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  writer_qos.history().depth = qos.depth;
  // Data sharing is Fast DDS to Fast DDS only; this peer stands for a node on another machine's vendor.
  writer_qos.data_sharing().off();
  // Payloads sized per sample (a cloud is megabytes, a joint state bytes), as rmw_fastrtps does.
  writer_qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
  writer_qos.reliable_writer_qos().times.heartbeatPeriod = kHeartbeatPeriod;
  dds::DataWriter* created =
      publisher_->create_datawriter(&topic(ros_topic, type), writer_qos, writer_listener_.get());
  if (created == nullptr) throw std::runtime_error("cannot create a writer of " + ros_topic);
  writers_.emplace(dds_topic_name(ros_topic), Writer{created, qos});
  return *created;
}

void Node::subscribe(const std::string& ros_topic, const RosType& type, const QosSpec& qos,
                     std::function<void(dds::DataReader&)> on_data) {
  if (readers_.count(dds_topic_name(ros_topic)) != 0)
    throw std::runtime_error(ros_topic + " has a reader already");
  dds::DataReaderQos reader_qos = dds::DATAREADER_QOS_DEFAULT;
  reader_qos.reliability().kind =
      qos.reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  reader_qos.durability().kind =
      qos.transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  reader_qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  reader_qos.history().depth = qos.depth;
  reader_qos.data_sharing().off();
  reader_qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
  listeners_.push_back(std::make_unique<ReaderListener>(std::move(on_data)));
  dds::DataReader* created =
      subscriber_->create_datareader(&topic(ros_topic, type), reader_qos, listeners_.back().get());
  if (created == nullptr) throw std::runtime_error("cannot create a reader of " + ros_topic);
  readers_.emplace(dds_topic_name(ros_topic), created);
}

void Node::unsubscribe(const std::string& ros_topic) {
  const auto found = readers_.find(dds_topic_name(ros_topic));
  if (found == readers_.end()) throw std::runtime_error(ros_topic + " has no reader");
  // Samples not taken yet go with the reader.
  found->second->set_listener(nullptr);
  check(subscriber_->delete_datareader(found->second), "deleting the reader of " + ros_topic);
  readers_.erase(found);
}

int Node::matched(const std::string& ros_topic) const {
  if (const auto writer = writers_.find(dds_topic_name(ros_topic)); writer != writers_.end()) {
    dds::PublicationMatchedStatus status;
    check(writer->second.writer->get_publication_matched_status(status), "matched status of " + ros_topic);
    return status.current_count;
  }
  if (const auto reader = readers_.find(dds_topic_name(ros_topic)); reader != readers_.end()) {
    dds::SubscriptionMatchedStatus status;
    check(reader->second->get_subscription_matched_status(status), "matched status of " + ros_topic);
    return status.current_count;
  }
  throw std::runtime_error(ros_topic + " has no writer or reader here");
}

void Node::wait_for_acknowledgments(std::chrono::nanoseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (const auto& [name, writer] : writers_) {
    if (!writer.qos.reliable) continue;
    const auto left = std::max(deadline - std::chrono::steady_clock::now(), std::chrono::nanoseconds(0));
    if (writer.writer->wait_for_acknowledgments(to_duration(left)) != ReturnCode_t::RETCODE_OK) {
      std::cerr << "ros2_peer: not every reader of " << name << " acknowledged in time\n";
    }
  }
}

}  // namespace ros2_peer
