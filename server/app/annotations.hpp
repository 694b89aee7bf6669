#pragma once

#include <cstdint>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/events.hpp"
#include "app/robot_link.hpp"
#include "storage/session_store.hpp"

namespace scanplan::server {

// The operator's marks on the map (victims, hazards, blocked ways, notes). Each is committed to
// the session before it is acknowledged, then announced to the browsers (WebSocket event
// "annotation") and to DDS (scanplan_Annotation, latched), in that order.
class Annotations {
 public:
  Annotations(SessionStore& session, AnnotationPublisher& dds, const Events& events);

  // Publishes every stored annotation on DDS: a restarted server's late joiners still get them.
  void republish();
  std::vector<Annotation> list() const;
  // Arguments as SessionStore::add_annotation; throws SessionStoreError when it cannot be stored.
  Annotation add(const std::string& kind, double x, double y, double z, const std::string& text,
                 const std::string& author);
  // False when there is no such annotation (or it was deleted already).
  bool remove(std::int64_t id, const std::string& by);

 private:
  SessionStore& session_;
  AnnotationPublisher& dds_;
  const Events& events_;
  // Storing and announcing happen together, so a deletion can never be announced before the
  // annotation it withdraws.
  std::mutex mutex_;
};

}  // namespace scanplan::server
