#pragma once

#include <chrono>
#include <cstddef>

namespace scanplan::http {

// Bounds that keep one misbehaving or malicious client from exhausting memory, file descriptors
// or the event loop's attention. Every limit that a request can hit maps to a specific status.
struct Limits {
  // Request line plus header fields (and chunked trailers); exceeding it answers 431.
  std::size_t max_header_bytes = 16 * 1024;
  // The request-target alone; exceeding it answers 414 so clients can tell "URL too long" apart.
  std::size_t max_target_bytes = 8 * 1024;
  // Many tiny fields cost more per byte than a few large ones; exceeding it answers 431.
  std::size_t max_header_count = 100;
  // A 300k-point PLY scan is ~5 MB; allow big uploads (whole recorded sessions). Answers 413.
  std::size_t max_body_bytes = 512ull << 20;
  // Beyond this, new connections get a 503 and are closed.
  std::size_t max_connections = 512;
  // Connections one client address may hold at once, so that one host (a broken script, a
  // flood) cannot take every connection from the operators; beyond it, 503.
  std::size_t max_connections_per_address = 256;
  // Total time from the first byte of a request to the end of its header section; bounds
  // slowloris-style clients that trickle one header byte at a time.
  std::chrono::milliseconds header_timeout{10000};
  // How long a keep-alive connection may sit with nothing to do between requests.
  std::chrono::milliseconds idle_timeout{60000};
  // Longest pause while a body is received or a response is sent. Reset by progress, so a large
  // upload on a slow link survives as long as bytes keep moving.
  std::chrono::milliseconds body_timeout{60000};
  // Once its header section is in, a request's body must keep up this average rate after the
  // grace period (408 otherwise): a client trickling a byte every few seconds resets
  // body_timeout for ever and holds the connection and its buffer. 16 kB/s (a 5 MB scan in five
  // minutes) is far below a rescue site's radio link.
  std::size_t min_body_bytes_per_s = 16 * 1024;
  std::chrono::milliseconds body_grace{10000};
  // Responses that may sit unsent on one connection before the server stops reading from it, so
  // a client that pipelines without reading cannot make the server buffer without bound.
  std::size_t max_pipelined = 32;
  // The same bound in bytes: responses queued unsent on one connection beyond which its
  // requests are no longer read (a shared body, OutputQueue, counts in full).
  std::size_t max_queued_bytes = 64ull << 20;
};

}  // namespace scanplan::http
