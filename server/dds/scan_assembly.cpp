#include "dds/scan_assembly.hpp"

#include <algorithm>

namespace scanplan::server {

ScanAssembly::Parts* ScanAssembly::parts(const Key& key, Clock::time_point now) {
  if (std::find(discarded_.begin(), discarded_.end(), key) != discarded_.end()) return nullptr;
  const auto [it, added] = open_.try_emplace(key);
  if (added) it->second.first_seen = now;
  return &it->second;
}

bool ScanAssembly::add_points(const Key& key, PointCloud points, Clock::time_point now) {
  Parts* p = parts(key, now);
  if (p) p->points = std::move(points);
  return p != nullptr;
}

bool ScanAssembly::add_pose(const Key& key, const Pose& pose, Clock::time_point now) {
  Parts* p = parts(key, now);
  if (p) p->pose = pose;
  return p != nullptr;
}

bool ScanAssembly::add_image(const Key& key, std::vector<std::uint8_t> jpeg,
                             Clock::time_point now) {
  Parts* p = parts(key, now);
  if (p) p->jpeg = std::move(jpeg);
  return p != nullptr;
}

bool ScanAssembly::add_camera(const Key& key, const PanoramaCamera& camera, Clock::time_point now) {
  Parts* p = parts(key, now);
  if (p) p->camera = camera;
  return p != nullptr;
}

ScanAssembly::Taken ScanAssembly::take(Clock::time_point now) {
  Taken out;
  for (auto it = open_.begin(); it != open_.end();) {
    Parts& s = it->second;
    const bool has_image = s.jpeg && s.camera;
    if (s.points && s.pose && (has_image || now - s.first_seen > config_.image_wait)) {
      out.complete.push_back({it->first.first, it->first.second, std::move(*s.points), *s.pose,
                              std::move(s.jpeg), s.camera});
      it = open_.erase(it);
    } else if (now - s.first_seen > config_.expiry) {
      out.dropped.push_back({it->first, s.points.has_value(), s.pose.has_value()});
      it = open_.erase(it);
    } else {
      ++it;
    }
  }
  while (open_.size() > config_.max_open) {
    const auto oldest = open_.begin();
    out.dropped.push_back(
        {oldest->first, oldest->second.points.has_value(), oldest->second.pose.has_value()});
    open_.erase(oldest);
  }
  return out;
}

std::size_t ScanAssembly::discard(const std::string& robot) {
  std::size_t parts = 0;
  for (auto it = open_.begin(); it != open_.end();) {
    if (it->first.first != robot) {
      ++it;
      continue;
    }
    const Parts& s = it->second;
    parts += s.points.has_value() + s.pose.has_value() + s.jpeg.has_value() + s.camera.has_value();
    discarded_.push_back(it->first);
    if (discarded_.size() > config_.max_discarded) discarded_.pop_front();
    it = open_.erase(it);
  }
  return parts;
}

}  // namespace scanplan::server
