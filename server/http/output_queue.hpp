#pragma once

#include <sys/types.h>

#include <cstddef>
#include <deque>
#include <memory>
#include <string>
#include <string_view>

namespace scanplan::http {

// The bytes a connection still has to send, in order: pieces it owns (status lines, headers,
// small bodies) and pieces shared with whoever made them (the map's Draco encoding, a layer
// image), which are never copied: forty clients fetching a 30 MB map cost one buffer, not forty
// (issue 16).
class OutputQueue {
 public:
  void append(std::string bytes);
  // `bytes` must stay valid while `owner` lives.
  void append_shared(std::shared_ptr<const void> owner, std::string_view bytes);

  bool empty() const { return pending_ == 0; }
  // Bytes queued and not yet sent, owned and shared alike.
  std::size_t pending_bytes() const { return pending_; }

  // Sends what the socket takes without blocking (sendmsg with MSG_NOSIGNAL, several pieces at
  // once). Returns the bytes sent, 0 when the socket would block, -1 on an error (errno set;
  // EINTR is retried).
  ssize_t send_some(int fd);

 private:
  struct Piece {
    std::string own;
    std::shared_ptr<const void> owner;  // set for a shared piece, whose bytes are `shared`
    std::string_view shared;
    std::size_t sent = 0;
    std::string_view bytes() const { return owner ? shared : std::string_view(own); }
  };
  std::deque<Piece> pieces_;
  std::size_t pending_ = 0;
};

}  // namespace scanplan::http
