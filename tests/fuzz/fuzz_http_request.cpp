// The HTTP request parser (server/http/request_parser): any bytes, in any pieces, end in a
// request, an error with a status, or a wait for more; never a crash or unbounded memory.
#include <cstdint>
#include <string_view>

#include "http/request_parser.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using scanplan::http::RequestParser;
  if (size < 1) return 0;
  // The first byte chooses how the rest is cut into pieces, as reads off a socket would be.
  const std::size_t piece = 1 + data[0] % 64;
  std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
  scanplan::http::Limits limits;
  limits.max_header_bytes = 4096;
  limits.max_target_bytes = 1024;
  limits.max_body_bytes = 1 << 16;
  RequestParser parser(limits);
  while (!rest.empty()) {
    const std::string_view chunk = rest.substr(0, piece);
    const std::size_t used = parser.feed(chunk);
    rest.remove_prefix(used);
    if (parser.state() == RequestParser::State::kError) break;
    if (parser.state() == RequestParser::State::kComplete) {
      const scanplan::http::Request r = parser.take();
      (void)r.keep_alive();
      (void)r.header("host");
    } else if (used < chunk.size()) {
      break;  // the parser takes what it is given unless it is done or failed
    } else if (parser.headers_complete()) {
      (void)parser.head().header("content-length");
    }
  }
  return 0;
}
