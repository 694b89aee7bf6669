#include "app/annotations.hpp"

#include <spdlog/spdlog.h>

#include "app/domain_json.hpp"

namespace scanplan::server {

Annotations::Annotations(SessionStore& session, AnnotationPublisher& dds, const Events& events)
    : session_(session), dds_(dds), events_(events) {}

void Annotations::republish() {
  std::lock_guard lock(mutex_);
  for (const Annotation& a : session_.annotations()) dds_.publish_annotation(a);
}

std::vector<Annotation> Annotations::list() const {
  return session_.annotations();
}

Annotation Annotations::add(const std::string& kind, double x, double y, double z,
                            const std::string& text, const std::string& author) {
  std::lock_guard lock(mutex_);
  const Annotation a = session_.add_annotation(kind, x, y, z, text, author);
  spdlog::info("annotation {} ({}) at ({:.2f}, {:.2f}, {:.2f}) by {}", a.id, a.kind, a.x, a.y, a.z,
               a.author);
  events_.publish("annotation", annotation_json(a));
  dds_.publish_annotation(a);
  return a;
}

bool Annotations::remove(std::int64_t id, const std::string& by) {
  std::lock_guard lock(mutex_);
  if (!session_.delete_annotation(id, by)) return false;
  spdlog::info("annotation {} deleted by {}", id, by);
  events_.publish("annotation_deleted", {{"id", id}, {"by", by}});
  dds_.withdraw_annotation(id);
  return true;
}

}  // namespace scanplan::server
