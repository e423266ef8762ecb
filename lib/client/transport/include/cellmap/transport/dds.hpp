// SPDX-License-Identifier: Apache-2.0
#pragma once
// A small RAII layer over the Cyclone DDS 0.10 C API: each class owns one DDS entity and deletes it (and so
// its children) when destroyed. Every call's return code is checked; failures throw cellmap::Error with
// Cyclone's reason (dds_strretcode). Entities are move-only: a copy would delete the entity twice.
//
// Thread safety: Cyclone's calls are thread-safe; these wrappers add no state of their own, except that one
// object must not be moved or destroyed while another thread uses it.

#include <dds/dds.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/security/credentials.hpp"

namespace cellmap::dds {

/// Throws Error("<what>: <Cyclone's reason>") when `rc` is negative; returns `rc` otherwise.
dds_return_t check(dds_return_t rc, const std::string& what);

/// Converts a timeout; negative or huge values mean "forever".
[[nodiscard]] dds_duration_t to_duration(std::chrono::nanoseconds timeout);

/// An owned QoS object.
class Qos final {
 public:
  Qos();
  ~Qos();
  Qos(const Qos& other);
  Qos& operator=(const Qos& other);
  /// RELIABLE (max blocking time 1 s), `transient_local` or VOLATILE durability, KEEP_LAST `depth` (0 means
  /// KEEP_ALL).
  static Qos make(bool transient_local, std::uint32_t depth);
  /// Writers only: when false, deleting the writer (a daemon restart) unregisters its instances without
  /// disposing them, so readers keep the data instead of seeing it removed.
  Qos& autodispose(bool on);
  /// BEST_EFFORT instead of RELIABLE: a reader then matches writers of either kind; a sample lost on the way
  /// is not sent again.
  Qos& best_effort();
  /// RESOURCE_LIMITS max_samples: the most samples an entity holds (a KEEP_ALL reader that holds them makes
  /// reliable writers wait).
  Qos& max_samples(std::uint32_t count);
  /// Readers and writers: puts the entity in one DDS partition (instead of the default partition ""). A name
  /// with '*' or '?' is a pattern: it matches every partition it fits (Cyclone matches patterns on either
  /// side, never a pattern with a pattern).
  Qos& partition(const std::string& name);
  /// Sets a named property (participants: e.g. DDS Security's "dds.sec.*").
  Qos& property(const std::string& name, const std::string& value);
  /// Sets USER_DATA to the bytes of `text` (no NUL), which peers see in discovery (ROS 2: "typehash=…;").
  Qos& user_data(const std::string& text);
  [[nodiscard]] const dds_qos_t* get() const { return qos_; }

 private:
  dds_qos_t* qos_;
};

/// Owns one entity handle; deleting it deletes its children too.
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  ~Entity();
  Entity(Entity&& other) noexcept;
  Entity& operator=(Entity&& other) noexcept;
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  [[nodiscard]] dds_entity_t get() const { return handle_; }
  [[nodiscard]] explicit operator bool() const { return handle_ > 0; }
  /// Deletes the entity now (no-op when empty).
  void reset();

 private:
  dds_entity_t handle_ = 0;
};

/// A domain participant. The configuration comes from CYCLONEDDS_URI as usual.
///
/// With a security setting it joins with DDS Security on (Cyclone's auth, access-control and crypto plugins,
/// configured through participant properties): it then talks only to participants of the same cell's CAs,
/// and creating a writer or reader its role's permissions do not grant throws ("Not Allowed By Security").
/// Every class of lib/client/transport takes its participant, so this one setting secures all of them.
///
/// Cyclone DDS 0.10 loads DDS Security once per domain and process, from the first participant's setting,
/// and gives every later participant of that process on that domain the same identity whatever it asked
/// for. So one process is one role on a domain: a participant whose setting differs from that of a live
/// participant of this process on the same domain is refused.
class Participant final : public Entity {
 public:
  /// @throws Error if the credentials are refused (security::check: "<file>: <reason>"), this process is on
  /// the domain with another setting, or the domain cannot be joined (bad id, bad CYCLONEDDS_URI, no usable
  /// interface).
  explicit Participant(std::uint32_t domain, const std::optional<security::Setting>& security = std::nullopt);
  /// Deletes the participant before giving back its claim on the domain's setting.
  ~Participant();
  Participant(Participant&& other) noexcept = default;
  /// The credentials it joined with; nullopt when DDS Security is off.
  [[nodiscard]] const std::optional<security::Credentials>& credentials() const { return credentials_; }

 private:
  // This participant's share of its domain's setting in this process, given back when it goes.
  class SettingClaim final {
   public:
    explicit SettingClaim(std::uint32_t domain) : domain_(domain) {}
    ~SettingClaim();
    SettingClaim(SettingClaim&& other) noexcept : domain_(other.domain_), held_(other.held_) {
      other.held_ = false;
    }
    SettingClaim& operator=(SettingClaim&&) = delete;

   private:
    std::uint32_t domain_;
    bool held_ = true;
  };
  struct Checked {};
  Participant(std::uint32_t domain, std::optional<security::Credentials> credentials, Checked);
  std::optional<security::Credentials> credentials_;
  SettingClaim claim_;
};

/// A topic of one generated type (its idlc descriptor, e.g. &cellmap_msg_Environment_desc).
class Topic final : public Entity {
 public:
  Topic(const Participant& participant, const dds_topic_descriptor_t* type, const std::string& name);
  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  std::string name_;
};

class Writer final : public Entity {
 public:
  Writer(const Participant& participant, const Topic& topic, const Qos& qos);
  /// Writes one sample of the topic's generated type. @throws Error naming the topic on failure (e.g. the
  /// reliable history stayed full for the max blocking time).
  void write(const void* sample) const;
  /// How many readers are matched right now.
  [[nodiscard]] std::uint32_t matched_readers() const;
  /// How many readers ever matched (grows by one per reader that joins, never shrinks).
  [[nodiscard]] std::uint32_t matched_readers_ever() const;
  /// Blocks until at least `count` readers matched or the timeout passed; true when they did.
  bool wait_for_readers(std::uint32_t count, std::chrono::nanoseconds timeout) const;
  /// Blocks until every matched reader acknowledged everything written; true when they did in time.
  bool wait_for_acks(std::chrono::nanoseconds timeout) const;

 private:
  std::string topic_;
};

class Reader final : public Entity {
 public:
  Reader(const Participant& participant, const Topic& topic, const Qos& qos);
  /// Takes every sample available now and calls `on_sample` with each one carrying data (a pointer to the
  /// topic's generated type, valid during the call, and its sample info). Samples without data (instance
  /// disposed, writer gone) are taken and skipped. Returns how many samples carried data.
  std::size_t take_all(
      const std::function<void(const void* sample, const dds_sample_info_t& info)>& on_sample) const;
  /// Like take_all(on_sample), and calls `on_gone` (after on_sample, if the sample carries data) for each
  /// sample telling that its instance lost its last writer (deleted, or its lease expired) or was disposed;
  /// only the key fields of a sample without data are set.
  std::size_t take_all(
      const std::function<void(const void* sample, const dds_sample_info_t& info)>& on_sample,
      const std::function<void(const void* key_sample)>& on_gone) const;
  /// How many writers are matched right now.
  [[nodiscard]] std::uint32_t matched_writers() const;

 private:
  std::string topic_;
};

/// Waits for data on several readers at once, interruptible from another thread through wake().
class WaitSet final {
 public:
  explicit WaitSet(const Participant& participant);
  /// Wakes the waiter whenever `reader` holds samples. The reader must stay alive until detach().
  void attach(const Reader& reader);
  void detach(const Reader& reader);
  /// Blocks until a reader attached has samples, wake() was called or the timeout passed. Returns false on
  /// timeout. A wake() is consumed by the wait it ends.
  bool wait(std::chrono::nanoseconds timeout);
  /// Makes the current or next wait() return; callable from any thread.
  void wake();

 private:
  struct Attached {
    dds_entity_t reader;
    Entity condition;
  };
  Entity waitset_;
  Entity guard_;
  std::vector<Attached> attached_;
};

}  // namespace cellmap::dds
