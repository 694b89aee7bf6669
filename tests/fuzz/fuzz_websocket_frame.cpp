// The WebSocket frame parser (server/http/websocket_frame), for client and server frames: any
// bytes end in messages, a close code, or a wait for more.
#include <cstdint>
#include <string_view>

#include "http/websocket_frame.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using scanplan::http::WebSocketFrameParser;
  if (size < 1) return 0;
  const auto sender = (data[0] & 1) ? scanplan::http::WebSocketFrameSender::kServer
                                    : scanplan::http::WebSocketFrameSender::kClient;
  const std::size_t piece = 1 + (data[0] >> 1) % 32;
  std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
  WebSocketFrameParser parser(1 << 16, sender);
  while (!rest.empty()) {
    const std::string_view chunk = rest.substr(0, piece);
    rest.remove_prefix(parser.feed(chunk));
    if (parser.state() == WebSocketFrameParser::State::kError) break;
    if (parser.state() == WebSocketFrameParser::State::kComplete) {
      (void)parser.take();
    } else if (parser.buffered_bytes() > (1 << 16)) {
      __builtin_trap();  // the limit must hold
    }
  }
  return 0;
}
