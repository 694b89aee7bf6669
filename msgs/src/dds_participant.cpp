#include "scanplan/msgs/dds_participant.hpp"

#include <cstdlib>
#include <memory>
#include <thread>

namespace scanplan::dds {

dds_return_t check(dds_return_t rc, std::string_view what) {
  if (rc < 0) {
    throw DdsError(std::string(what) + " failed: " + dds_strretcode(rc));
  }
  return rc;
}

std::string default_config() {
  return "<CycloneDDS><Domain Id=\"any\">"
         "<General><MaxMessageSize>65500B</MaxMessageSize></General>"
         "<Internal><SocketReceiveBufferSize min=\"default\" max=\"4MiB\"/></Internal>"
         "</Domain></CycloneDDS>";
}

Participant::Participant(std::uint32_t domain_id) {
  std::string config = default_config();
  if (const char* uri = std::getenv("CYCLONEDDS_URI"); uri && *uri) {
    config += ",";
    config += uri;
  }
  domain_ = dds_create_domain(domain_id, config.c_str());
  // Another participant in this process already made the domain: share its settings.
  if (domain_ == DDS_RETCODE_PRECONDITION_NOT_MET)
    domain_ = 0;
  else
    check(domain_, "creating DDS domain " + std::to_string(domain_id));
  participant_ = dds_create_participant(domain_id, nullptr, nullptr);
  if (participant_ < 0) {
    if (domain_ > 0) dds_delete(domain_);
    check(participant_, "creating a DDS participant on domain " + std::to_string(domain_id));
  }
}

Participant::~Participant() {
  dds_delete(participant_);
  if (domain_ > 0) dds_delete(domain_);
}

dds_entity_t Participant::topic(const dds_topic_descriptor_t& type, const std::string& name) {
  auto it = topics_.find(name);
  if (it != topics_.end()) return it->second;
  const dds_entity_t t = dds_create_topic(participant_, &type, name.c_str(), nullptr, nullptr);
  check(t, "creating topic " + name);
  topics_.emplace(name, t);
  return t;
}

namespace {

struct QosDeleter {
  void operator()(dds_qos_t* q) const { dds_delete_qos(q); }
};

std::unique_ptr<dds_qos_t, QosDeleter> make_qos(QosKind kind) {
  std::unique_ptr<dds_qos_t, QosDeleter> q(dds_create_qos());
  dds_qset_reliability(q.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  switch (kind) {
    case QosKind::kScanData:
      // Four scans is minutes of robot time; a reader that far behind has bigger problems.
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, 4);
      // Only bridges write scan data: the server must see one vanish mid-scan.
      dds_qset_liveliness(q.get(), DDS_LIVELINESS_AUTOMATIC,
                          DDS_MSECS(kBridgeLivelinessLease.count()));
      break;
    case QosKind::kCommand:
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_ALL, 0);
      dds_qset_resource_limits(q.get(), 64, 64, 64);
      break;
    case QosKind::kStatus:
      // Keyed by robot_id, so the depth is per robot: one robot's heartbeats never push out
      // another's status. Not only the latest: with a depth of 1 a refusal followed at once by
      // the robot's idle heartbeat reached the server as the heartbeat alone — a refused move
      // stayed "driving" (issue 18). 16 samples are 16 s of one robot's heartbeats.
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, 16);
      // The status writer is how the server knows which robot a bridge speaks for, and its
      // lease is how it knows the bridge is still there.
      dds_qset_liveliness(q.get(), DDS_LIVELINESS_AUTOMATIC,
                          DDS_MSECS(kBridgeLivelinessLease.count()));
      break;
    case QosKind::kLatched:
      dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, 1);
      dds_qset_durability(q.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
      break;
  }
  return q;
}

}  // namespace

dds_entity_t Participant::writer(const dds_topic_descriptor_t& type, const std::string& name,
                                 QosKind qos) {
  const dds_entity_t w =
      dds_create_writer(participant_, topic(type, name), make_qos(qos).get(), nullptr);
  return check(w, "creating a writer for " + name);
}

dds_entity_t Participant::reader(const dds_topic_descriptor_t& type, const std::string& name,
                                 QosKind qos, const dds_listener_t* listener) {
  const dds_entity_t r =
      dds_create_reader(participant_, topic(type, name), make_qos(qos).get(), listener);
  return check(r, "creating a reader for " + name);
}

ReadWaiter::ReadWaiter(dds_entity_t participant, std::initializer_list<dds_entity_t> readers) {
  waitset_ = check(dds_create_waitset(participant), "dds_create_waitset");
  for (const dds_entity_t r : readers) {
    check(dds_set_status_mask(r, DDS_DATA_AVAILABLE_STATUS), "dds_set_status_mask");
    check(dds_waitset_attach(waitset_, r, r), "dds_waitset_attach");
  }
}

ReadWaiter::~ReadWaiter() {
  dds_delete(waitset_);
}

bool ReadWaiter::wait(std::chrono::milliseconds timeout) {
  const dds_return_t n = dds_waitset_wait(waitset_, nullptr, 0, DDS_MSECS(timeout.count()));
  check(n, "dds_waitset_wait");
  return n > 0;
}

bool wait_for_reader(dds_entity_t writer, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    dds_publication_matched_status_t st;
    check(dds_get_publication_matched_status(writer, &st), "dds_get_publication_matched_status");
    if (st.current_count > 0) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace scanplan::dds
