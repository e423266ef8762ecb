// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/dds.hpp"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <mutex>
#include <thread>
#include <utility>

#include "cellmap/common/error.hpp"
#include "cellmap/transport/input_limits.hpp"

namespace cellmap::dds {

dds_return_t check(dds_return_t rc, const std::string& what) {
  if (rc < 0) throw Error(what + ": " + dds_strretcode(rc));
  return rc;
}

dds_duration_t to_duration(std::chrono::nanoseconds timeout) {
  if (timeout.count() < 0 || timeout >= std::chrono::hours(24 * 365)) return DDS_INFINITY;
  return static_cast<dds_duration_t>(timeout.count());
}

Qos::Qos() : qos_(dds_create_qos()) {}
Qos::~Qos() {
  dds_delete_qos(qos_);
}
Qos::Qos(const Qos& other) : qos_(dds_create_qos()) {
  dds_copy_qos(qos_, other.qos_);
}
Qos& Qos::operator=(const Qos& other) {
  if (this != &other) dds_copy_qos(qos_, other.qos_);
  return *this;
}

Qos Qos::make(bool transient_local, std::uint32_t depth) {
  Qos qos;
  dds_qset_reliability(qos.qos_, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos.qos_, transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  const dds_history_kind_t kind = depth == 0 ? DDS_HISTORY_KEEP_ALL : DDS_HISTORY_KEEP_LAST;
  dds_qset_history(qos.qos_, kind, static_cast<int32_t>(depth));
  // Cyclone keeps for late joiners what the durability-service history says (default KEEP_LAST 1), not the
  // writer history: without this a transient-local KEEP_LAST N writer would hand a late joiner one sample.
  if (transient_local) {
    dds_qset_durability_service(qos.qos_, 0, kind, static_cast<int32_t>(depth), DDS_LENGTH_UNLIMITED,
                                DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  }
  return qos;
}

Qos& Qos::autodispose(bool on) {
  dds_qset_writer_data_lifecycle(qos_, on);
  return *this;
}

Qos& Qos::best_effort() {
  dds_qset_reliability(qos_, DDS_RELIABILITY_BEST_EFFORT, 0);
  return *this;
}

Qos& Qos::max_samples(std::uint32_t count) {
  dds_qset_resource_limits(qos_, static_cast<int32_t>(count), DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  return *this;
}

Qos& Qos::partition(const std::string& name) {
  dds_qset_partition1(qos_, name.c_str());
  return *this;
}

Qos& Qos::property(const std::string& name, const std::string& value) {
  dds_qset_prop(qos_, name.c_str(), value.c_str());
  return *this;
}

Qos& Qos::user_data(const std::string& text) {
  dds_qset_userdata(qos_, text.data(), text.size());
  return *this;
}

Entity::~Entity() {
  reset();
}

Entity::Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}

Entity& Entity::operator=(Entity&& other) noexcept {
  if (this != &other) {
    reset();
    handle_ = std::exchange(other.handle_, 0);
  }
  return *this;
}

void Entity::reset() {
  // A child already deleted with its parent reports "already deleted": nothing left to free.
  if (handle_ > 0) (void)dds_delete(handle_);
  handle_ = 0;
}

namespace {

// Cyclone's three DDS Security plugins (Debian's libddsc0debian ships them; found by their bare names) and
// the role's files, as the participant properties of the DDS Security specification name them.
Qos security_qos(const security::Credentials& credentials) {
  const auto file = [](const std::filesystem::path& path) { return "file:" + path.string(); };
  const security::RoleFiles& files = credentials.files;
  Qos qos;
  qos.property("dds.sec.auth.library.path", "dds_security_auth")
      .property("dds.sec.auth.library.init", "init_authentication")
      .property("dds.sec.auth.library.finalize", "finalize_authentication")
      .property("dds.sec.crypto.library.path", "dds_security_crypto")
      .property("dds.sec.crypto.library.init", "init_crypto")
      .property("dds.sec.crypto.library.finalize", "finalize_crypto")
      .property("dds.sec.access.library.path", "dds_security_ac")
      .property("dds.sec.access.library.init", "init_access_control")
      .property("dds.sec.access.library.finalize", "finalize_access_control")
      .property("dds.sec.auth.identity_ca", file(files.identity_ca))
      .property("dds.sec.auth.identity_certificate", file(files.certificate))
      .property("dds.sec.auth.private_key", file(files.private_key))
      .property("dds.sec.access.permissions_ca", file(files.permissions_ca))
      .property("dds.sec.access.governance", file(files.governance))
      .property("dds.sec.access.permissions", file(files.permissions));
  // Cyclone's own name for it: the DDS Security specification names no revocation list.
  std::error_code ec;
  if (std::filesystem::exists(files.revocations, ec))
    qos.property("org.eclipse.cyclonedds.sec.auth.crl", file(files.revocations));
  return qos;
}

// The DDS Security setting of each domain this process is on, with how many live participants hold it and
// the domain entity made for them.
struct DomainSetting {
  std::string security;
  int participants = 0;
  dds_entity_t domain = 0;
};
struct DomainSettings {
  std::mutex mutex;
  std::map<std::uint32_t, DomainSetting> held;
};
DomainSettings& domain_settings() {
  static DomainSettings settings;
  return settings;
}

std::string describe(const std::optional<security::Credentials>& credentials) {
  if (!credentials) return "without DDS Security";
  return "as " + credentials->subject + " (" + credentials->files.certificate.parent_path().string() + ")";
}

// The domain as Cyclone DDS runs it for this process, made before its first participant so that no sample
// larger than kMaxSampleBytes reaches a reader (Internal/MaxSampleSize). The
// user's CYCLONEDDS_URI comes after it and wins where it sets the same. A domain that exists already (made
// by a participant created elsewhere) is left as it is: 0.
dds_entity_t create_domain(std::uint32_t domain) {
  std::string config = "<CycloneDDS><Domain Id=\"any\"><Internal><MaxSampleSize>" +
                       std::to_string(transport::kMaxSampleBytes) +
                       " B</MaxSampleSize></Internal></Domain></CycloneDDS>";
  const char* uri = std::getenv("CYCLONEDDS_URI");
  if (uri != nullptr && *uri != '\0') config += std::string(",") + uri;
  const dds_entity_t entity = dds_create_domain(domain, config.c_str());
  if (entity == DDS_RETCODE_PRECONDITION_NOT_MET) return 0;
  return check(entity, "cannot join DDS domain " + std::to_string(domain) + " (check CYCLONEDDS_URI)");
}

void claim_setting(std::uint32_t domain, const std::optional<security::Credentials>& credentials) {
  DomainSettings& settings = domain_settings();
  const std::lock_guard<std::mutex> lock(settings.mutex);
  DomainSetting& setting = settings.held[domain];
  const std::string wanted = describe(credentials);
  if (setting.participants > 0 && setting.security != wanted) {
    throw Error("cannot join DDS domain " + std::to_string(domain) + " " + wanted +
                ": this process is on it " + setting.security +
                ", and Cyclone DDS takes one security setting per domain and process");
  }
  if (setting.participants == 0) {
    try {
      setting.domain = create_domain(domain);
    } catch (...) {
      settings.held.erase(domain);
      throw;
    }
  }
  setting.security = wanted;
  ++setting.participants;
}

void release_setting(std::uint32_t domain) {
  DomainSettings& settings = domain_settings();
  const std::lock_guard<std::mutex> lock(settings.mutex);
  const auto it = settings.held.find(domain);
  if (it == settings.held.end() || --it->second.participants > 0) return;
  if (it->second.domain > 0) (void)dds_delete(it->second.domain);
  settings.held.erase(it);
}

dds_entity_t create_participant(std::uint32_t domain,
                                const std::optional<security::Credentials>& credentials) {
  const std::string what = "cannot join DDS domain " + std::to_string(domain);
  if (!credentials)
    return check(dds_create_participant(domain, nullptr, nullptr), what + " (check CYCLONEDDS_URI)");
  const Qos qos = security_qos(*credentials);
  return check(dds_create_participant(domain, qos.get(), nullptr),
               what + " as " + credentials->subject + " with DDS Security");
}

// Claims the domain's setting first, so a participant that would get another one is never created.
dds_entity_t join(std::uint32_t domain, const std::optional<security::Credentials>& credentials) {
  claim_setting(domain, credentials);
  try {
    return create_participant(domain, credentials);
  } catch (...) {
    release_setting(domain);
    throw;
  }
}

}  // namespace

Participant::Participant(std::uint32_t domain, const std::optional<security::Setting>& security)
    : Participant(domain, security ? std::optional(security::check(*security, domain)) : std::nullopt,
                  Checked{}) {}

Participant::Participant(std::uint32_t domain, std::optional<security::Credentials> credentials, Checked)
    : Entity(join(domain, credentials)), credentials_(std::move(credentials)), claim_(domain) {}

Participant::~Participant() {
  reset();
}

Participant::SettingClaim::~SettingClaim() {
  if (held_) release_setting(domain_);
}

Topic::Topic(const Participant& participant, const dds_topic_descriptor_t* type, const std::string& name)
    : Entity(check(dds_create_topic(participant.get(), type, name.c_str(), nullptr, nullptr),
                   "cannot create DDS topic " + name)),
      name_(name) {}

Writer::Writer(const Participant& participant, const Topic& topic, const Qos& qos)
    : Entity(check(dds_create_writer(participant.get(), topic.get(), qos.get(), nullptr),
                   "cannot create a writer on " + topic.name())),
      topic_(topic.name()) {}

void Writer::write(const void* sample) const {
  check(dds_write(get(), sample), "cannot write to " + topic_);
}

std::uint32_t Writer::matched_readers() const {
  dds_publication_matched_status_t status;
  check(dds_get_publication_matched_status(get(), &status), "cannot get the readers of " + topic_);
  return status.current_count;
}

std::uint32_t Writer::matched_readers_ever() const {
  dds_publication_matched_status_t status;
  check(dds_get_publication_matched_status(get(), &status), "cannot get the readers of " + topic_);
  return status.total_count;
}

bool Writer::wait_for_readers(std::uint32_t count, std::chrono::nanoseconds timeout) const {
  // Matching is a discovery event without a waitable condition of its own here; poll it briefly.
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (matched_readers() < count) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

bool Writer::wait_for_acks(std::chrono::nanoseconds timeout) const {
  const dds_return_t rc = dds_wait_for_acks(get(), to_duration(timeout));
  if (rc == DDS_RETCODE_TIMEOUT) return false;
  check(rc, "cannot wait for acknowledgements on " + topic_);
  return true;
}

Reader::Reader(const Participant& participant, const Topic& topic, const Qos& qos)
    : Entity(check(dds_create_reader(participant.get(), topic.get(), qos.get(), nullptr),
                   "cannot create a reader on " + topic.name())),
      topic_(topic.name()) {}

std::size_t Reader::take_all(
    const std::function<void(const void* sample, const dds_sample_info_t& info)>& on_sample) const {
  return take_all(on_sample, {});
}

std::size_t Reader::take_all(
    const std::function<void(const void* sample, const dds_sample_info_t& info)>& on_sample,
    const std::function<void(const void* key_sample)>& on_gone) const {
  constexpr std::size_t kBatch = 32;
  std::size_t with_data = 0;
  for (;;) {
    void* samples[kBatch] = {};
    dds_sample_info_t infos[kBatch];
    // Null buffers: Cyclone lends its own samples, returned below even if a callback throws.
    const dds_return_t n =
        check(dds_take(get(), samples, infos, kBatch, kBatch), "cannot take from " + topic_);
    if (n == 0) return with_data;
    struct Loan {
      dds_entity_t reader;
      void** samples;
      dds_return_t n;
      ~Loan() { (void)dds_return_loan(reader, samples, n); }
    } loan{get(), samples, n};
    for (dds_return_t i = 0; i < n; ++i) {
      if (infos[i].valid_data) {
        ++with_data;
        on_sample(samples[i], infos[i]);
      }
      if (on_gone && infos[i].instance_state != DDS_IST_ALIVE) on_gone(samples[i]);
    }
  }
}

std::uint32_t Reader::matched_writers() const {
  dds_subscription_matched_status_t status;
  check(dds_get_subscription_matched_status(get(), &status), "cannot get the writers of " + topic_);
  return status.current_count;
}

WaitSet::WaitSet(const Participant& participant)
    : waitset_(check(dds_create_waitset(participant.get()), "cannot create a DDS waitset")),
      guard_(check(dds_create_guardcondition(participant.get()), "cannot create a DDS guard condition")) {
  check(dds_waitset_attach(waitset_.get(), guard_.get(), 0), "cannot attach a guard condition");
}

void WaitSet::attach(const Reader& reader) {
  Entity condition(
      check(dds_create_readcondition(reader.get(), DDS_ANY_STATE), "cannot create a read condition"));
  check(dds_waitset_attach(waitset_.get(), condition.get(), reader.get()),
        "cannot attach a reader to a waitset");
  attached_.push_back({reader.get(), std::move(condition)});
}

void WaitSet::detach(const Reader& reader) {
  const auto it = std::find_if(attached_.begin(), attached_.end(),
                               [&](const Attached& a) { return a.reader == reader.get(); });
  if (it == attached_.end()) return;
  check(dds_waitset_detach(waitset_.get(), it->condition.get()), "cannot detach a reader from a waitset");
  attached_.erase(it);
}

bool WaitSet::wait(std::chrono::nanoseconds timeout) {
  dds_attach_t triggered[8];
  const dds_return_t n =
      check(dds_waitset_wait(waitset_.get(), triggered, 8, to_duration(timeout)), "cannot wait on a waitset");
  bool guard_hit = false;
  for (dds_return_t i = 0; i < std::min<dds_return_t>(n, 8); ++i) guard_hit |= triggered[i] == 0;
  if (guard_hit) check(dds_set_guardcondition(guard_.get(), false), "cannot reset a guard condition");
  return n > 0;
}

void WaitSet::wake() {
  check(dds_set_guardcondition(guard_.get(), true), "cannot set a guard condition");
}

}  // namespace cellmap::dds
