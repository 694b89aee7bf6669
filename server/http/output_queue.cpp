#include "http/output_queue.hpp"

#include <sys/socket.h>
#include <sys/uio.h>

#include <cerrno>

namespace scanplan::http {
namespace {

// Pieces handed to one sendmsg; the kernel's limit (IOV_MAX) is far above.
constexpr std::size_t kMaxIov = 16;
// Small owned pieces are merged into the one before, so a pipelined burst of small responses
// stays a few large pieces.
constexpr std::size_t kMergeBelow = 64 * 1024;

}  // namespace

void OutputQueue::append(std::string bytes) {
  if (bytes.empty()) return;
  pending_ += bytes.size();
  if (!pieces_.empty() && !pieces_.back().owner && pieces_.back().own.size() < kMergeBelow) {
    pieces_.back().own += bytes;
    return;
  }
  Piece p;
  p.own = std::move(bytes);
  pieces_.push_back(std::move(p));
}

void OutputQueue::append_shared(std::shared_ptr<const void> owner, std::string_view bytes) {
  if (bytes.empty()) return;
  pending_ += bytes.size();
  Piece p;
  p.owner = std::move(owner);
  p.shared = bytes;
  pieces_.push_back(std::move(p));
}

ssize_t OutputQueue::send_some(int fd) {
  if (pieces_.empty()) return 0;
  iovec iov[kMaxIov];
  std::size_t count = 0;
  for (const Piece& p : pieces_) {
    if (count == kMaxIov) break;
    const std::string_view rest = p.bytes().substr(p.sent);
    iov[count].iov_base = const_cast<char*>(rest.data());
    iov[count].iov_len = rest.size();
    ++count;
  }
  msghdr msg{};
  msg.msg_iov = iov;
  msg.msg_iovlen = count;
  ssize_t n;
  do {
    n = ::sendmsg(fd, &msg, MSG_NOSIGNAL);
  } while (n < 0 && errno == EINTR);
  if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK) ? 0 : -1;
  auto left = static_cast<std::size_t>(n);
  pending_ -= left;
  while (left > 0) {
    Piece& front = pieces_.front();
    const std::size_t rest = front.bytes().size() - front.sent;
    if (left < rest) {
      front.sent += left;
      break;
    }
    left -= rest;
    pieces_.pop_front();
  }
  return n;
}

}  // namespace scanplan::http
