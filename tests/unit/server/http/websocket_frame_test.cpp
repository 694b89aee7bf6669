#include "http/websocket_frame.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "http/utf8.hpp"
#include "websocket_test_support.hpp"

namespace scanplan::http {
namespace {

using test::client_frame;
using test::close_payload;

constexpr std::uint8_t kCont = 0x0;
constexpr std::uint8_t kText = 0x1;
constexpr std::uint8_t kBinary = 0x2;
constexpr std::uint8_t kClose = 0x8;
constexpr std::uint8_t kPing = 0x9;
constexpr std::uint8_t kPong = 0xA;

struct Outcome {
  std::vector<WebSocketMessage> messages;
  WebSocketFrameParser::State state = WebSocketFrameParser::State::kIncomplete;
  std::uint16_t error_code = 0;
};

// Feeds the pieces in order, taking messages as they complete, the way the hub drives the parser.
Outcome parse_pieces(const std::vector<std::string_view>& pieces, std::size_t max = 1 << 20) {
  WebSocketFrameParser parser(max);
  Outcome out;
  for (std::string_view piece : pieces) {
    while (true) {
      piece.remove_prefix(parser.feed(piece));
      if (parser.state() == WebSocketFrameParser::State::kComplete) {
        out.messages.push_back(parser.take());
        continue;
      }
      break;
    }
    if (parser.state() == WebSocketFrameParser::State::kError) break;
    EXPECT_TRUE(piece.empty()) << "an incomplete parser must consume everything";
  }
  out.state = parser.state();
  out.error_code = parser.error_code();
  return out;
}

Outcome parse(std::string_view bytes, std::size_t max = 1 << 20) {
  return parse_pieces({bytes}, max);
}

void expect_message(const WebSocketMessage& m, WebSocketOpcode opcode, const std::string& payload) {
  EXPECT_EQ(m.opcode, opcode);
  EXPECT_EQ(m.payload, payload);
}

std::string pattern(std::size_t n) {
  std::string s(n, '\0');
  for (std::size_t i = 0; i < n; ++i) s[i] = static_cast<char>(i * 7 + 3);
  return s;
}

TEST(WebSocketFrameParser, DecodesTheMaskedHelloFromRfc6455) {
  // RFC 6455 §5.7: "A single-frame masked text message".
  const std::string bytes = "\x81\x85\x37\xfa\x21\x3d\x7f\x9f\x4d\x51\x58";
  const Outcome out = parse(bytes);
  ASSERT_EQ(out.messages.size(), 1u);
  expect_message(out.messages[0], WebSocketOpcode::kText, "Hello");
  EXPECT_EQ(out.state, WebSocketFrameParser::State::kIncomplete);
}

TEST(WebSocketFrameParser, DecodesTheFragmentedHelloFromRfc6455) {
  // RFC 6455 §5.7 with masks: "Hel" then "lo".
  const std::string bytes =
      client_frame(kText, "Hel", false, true, {1, 2, 3, 4}) + client_frame(kCont, "lo", true);
  const Outcome out = parse(bytes);
  ASSERT_EQ(out.messages.size(), 1u);
  expect_message(out.messages[0], WebSocketOpcode::kText, "Hello");
}

// A stream exercising every length encoding, fragmentation with a control frame in the middle,
// an empty message and a close frame.
std::string mixed_stream() {
  std::string s;
  s += client_frame(kText, "first");
  s += client_frame(kBinary, pattern(126));    // 16-bit length, smallest
  s += client_frame(kBinary, pattern(65535));  // 16-bit length, largest
  s += client_frame(kBinary, pattern(65536));  // 64-bit length
  s += client_frame(kText, "frag", false, true, {9, 8, 7, 6});
  s += client_frame(kPing, "in between");
  s += client_frame(kCont, "men", false, true, {0, 0, 0, 0});
  s += client_frame(kPong, "");
  s += client_frame(kCont, "ted \xC3\xA9", true, true, {0xff, 0x00, 0xaa, 0x55});
  s += client_frame(kText, "");
  s += client_frame(kClose, close_payload(1000, "bye"));
  return s;
}

void expect_mixed_messages(const Outcome& out) {
  ASSERT_EQ(out.state, WebSocketFrameParser::State::kIncomplete);
  ASSERT_EQ(out.messages.size(), 9u);
  expect_message(out.messages[0], WebSocketOpcode::kText, "first");
  expect_message(out.messages[1], WebSocketOpcode::kBinary, pattern(126));
  expect_message(out.messages[2], WebSocketOpcode::kBinary, pattern(65535));
  expect_message(out.messages[3], WebSocketOpcode::kBinary, pattern(65536));
  expect_message(out.messages[4], WebSocketOpcode::kPing, "in between");
  expect_message(out.messages[5], WebSocketOpcode::kPong, "");
  expect_message(out.messages[6], WebSocketOpcode::kText, "fragmented \xC3\xA9");
  expect_message(out.messages[7], WebSocketOpcode::kText, "");
  expect_message(out.messages[8], WebSocketOpcode::kClose, "bye");
  EXPECT_EQ(out.messages[8].close_code, 1000);
}

TEST(WebSocketFrameParser, SameResultAtEverySplitPoint) {
  const std::string s = mixed_stream();
  expect_mixed_messages(parse(s));
  // The interesting split points are inside the small frames at both ends; every one of them
  // is covered, and inside the long payloads a stride keeps the test fast.
  for (std::size_t split = 0; split <= s.size();
       split += (split < 300 || split > s.size() - 300) ? 1 : 997) {
    SCOPED_TRACE("split at " + std::to_string(split));
    const std::string_view v(s);
    expect_mixed_messages(parse_pieces({v.substr(0, split), v.substr(split)}));
  }
}

TEST(WebSocketFrameParser, SameResultOneByteAtATime) {
  std::string s;
  s += client_frame(kText, "one", false);
  s += client_frame(kPing, "p");
  s += client_frame(kCont, "two");
  s += client_frame(kBinary, pattern(300));
  s += client_frame(kClose, "");
  std::vector<std::string_view> bytes;
  for (std::size_t i = 0; i < s.size(); ++i) bytes.push_back(std::string_view(s).substr(i, 1));
  const Outcome out = parse_pieces(bytes);
  ASSERT_EQ(out.messages.size(), 4u);
  expect_message(out.messages[0], WebSocketOpcode::kPing, "p");
  expect_message(out.messages[1], WebSocketOpcode::kText, "onetwo");
  expect_message(out.messages[2], WebSocketOpcode::kBinary, pattern(300));
  expect_message(out.messages[3], WebSocketOpcode::kClose, "");
  EXPECT_EQ(out.messages[3].close_code, websocket_close::kNoStatus);
}

TEST(WebSocketFrameParser, StopsAfterEachMessage) {
  const std::string s = client_frame(kText, "a") + client_frame(kText, "b");
  WebSocketFrameParser parser(1024);
  const std::size_t used = parser.feed(s);
  EXPECT_EQ(used, s.size() / 2);
  ASSERT_EQ(parser.state(), WebSocketFrameParser::State::kComplete);
  EXPECT_EQ(parser.feed(std::string_view(s).substr(used)), 0u) << "nothing before take()";
  EXPECT_EQ(parser.take().payload, "a");
  EXPECT_EQ(parser.feed(std::string_view(s).substr(used)), s.size() / 2);
  EXPECT_EQ(parser.take().payload, "b");
}

TEST(WebSocketFrameParser, TakeBeforeCompleteThrows) {
  WebSocketFrameParser parser(1024);
  EXPECT_THROW(parser.take(), std::logic_error);
}

TEST(WebSocketFrameParser, UnmaskedFrameIsAProtocolErrorAtOnce) {
  const std::string frame = client_frame(kText, "hello", true, false);
  WebSocketFrameParser parser(1024);
  EXPECT_EQ(parser.feed(std::string_view(frame).substr(0, 2)), 2u);
  EXPECT_EQ(parser.state(), WebSocketFrameParser::State::kError) << "decided from the header";
  EXPECT_EQ(parser.error_code(), websocket_close::kProtocolError);
  EXPECT_NE(parser.error_message().find("masked"), std::string::npos) << parser.error_message();
  EXPECT_EQ(parser.feed("more"), 0u) << "nothing is consumed after an error";
}

TEST(WebSocketFrameParser, ControlFrameRules) {
  EXPECT_EQ(parse(client_frame(kPing, pattern(125))).messages.size(), 1u) << "125 is allowed";
  EXPECT_EQ(parse(client_frame(kPing, pattern(126))).error_code, websocket_close::kProtocolError);
  EXPECT_EQ(parse(client_frame(kPong, pattern(200))).error_code, websocket_close::kProtocolError);
  EXPECT_EQ(parse(client_frame(kPing, "x", false)).error_code, websocket_close::kProtocolError)
      << "control frames cannot be fragmented";
  EXPECT_EQ(parse(client_frame(kClose, pattern(126))).error_code, websocket_close::kProtocolError);
}

TEST(WebSocketFrameParser, FragmentationRules) {
  EXPECT_EQ(parse(client_frame(kCont, "orphan")).error_code, websocket_close::kProtocolError)
      << "continuation without a message";
  EXPECT_EQ(parse(client_frame(kText, "a", false) + client_frame(kText, "b")).error_code,
            websocket_close::kProtocolError)
      << "a new message while one is unfinished";
  EXPECT_EQ(parse(client_frame(kBinary, "a", false) + client_frame(kText, "b")).error_code,
            websocket_close::kProtocolError);
  const Outcome many = parse(client_frame(kBinary, "a", false) + client_frame(kCont, "", false) +
                             client_frame(kCont, "b", false) + client_frame(kCont, "c"));
  ASSERT_EQ(many.messages.size(), 1u);
  expect_message(many.messages[0], WebSocketOpcode::kBinary, "abc");
}

TEST(WebSocketFrameParser, ReservedBitsAndOpcodesAreProtocolErrors) {
  std::string rsv1 = client_frame(kText, "x");
  rsv1[0] = static_cast<char>(rsv1[0] | 0x40);  // RSV1 would mean permessage-deflate
  EXPECT_EQ(parse(rsv1).error_code, websocket_close::kProtocolError);
  for (const std::uint8_t op : std::initializer_list<std::uint8_t>{0x3, 0x7, 0xB, 0xF}) {
    EXPECT_EQ(parse(client_frame(op, "x")).error_code, websocket_close::kProtocolError)
        << "opcode " << int(op);
  }
}

TEST(WebSocketFrameParser, OversizedMessageIsRefusedFromItsHeader) {
  const std::string frame = client_frame(kBinary, pattern(2000));
  WebSocketFrameParser parser(1000);
  // Header only: 2 bytes, 2 length bytes, 4 mask bytes.
  EXPECT_EQ(parser.feed(std::string_view(frame).substr(0, 8)), 8u);
  EXPECT_EQ(parser.state(), WebSocketFrameParser::State::kError);
  EXPECT_EQ(parser.error_code(), websocket_close::kMessageTooBig);
  EXPECT_EQ(parser.buffered_bytes(), 0u);

  EXPECT_EQ(parse(client_frame(kBinary, pattern(1000)), 1000).messages.size(), 1u)
      << "exactly the limit is fine";
  EXPECT_EQ(
      parse(client_frame(kBinary, pattern(600), false) + client_frame(kCont, pattern(401)), 1000)
          .error_code,
      websocket_close::kMessageTooBig)
      << "the limit applies to the reassembled message";
}

TEST(WebSocketFrameParser, HugeAnnouncedLengthsDoNotAllocate) {
  // 2^62 bytes announced: refused without trying to reserve it.
  std::string frame = "\x82\xFF";
  frame += std::string("\x40\x00\x00\x00\x00\x00\x00\x00", 8);
  frame += "abcd";
  EXPECT_EQ(parse(frame).error_code, websocket_close::kMessageTooBig);
  // The most significant bit of a 64-bit length must be 0.
  std::string msb = "\x82\xFF";
  msb += std::string("\x80\x00\x00\x00\x00\x00\x00\x01", 8);
  msb += "abcd";
  EXPECT_EQ(parse(msb).error_code, websocket_close::kProtocolError);
}

TEST(WebSocketFrameParser, TextMustBeUtf8) {
  EXPECT_EQ(parse(client_frame(kText, "bad \xFF byte")).error_code,
            websocket_close::kInvalidPayload);
  EXPECT_EQ(parse(client_frame(kText, "\xED\xA0\x80")).error_code, websocket_close::kInvalidPayload)
      << "a UTF-16 surrogate";
  EXPECT_EQ(parse(client_frame(kText, "cut \xE2\x82")).error_code, websocket_close::kInvalidPayload)
      << "a truncated sequence at the end of the message";
  // A character split across fragments is fine: validity is a property of the message.
  const Outcome split = parse(client_frame(kText, "\xE2\x82", false) + client_frame(kCont, "\xAC"));
  ASSERT_EQ(split.messages.size(), 1u);
  EXPECT_EQ(split.messages[0].payload, "\xE2\x82\xAC");
  EXPECT_EQ(parse(client_frame(kBinary, "\xFF\xFE")).messages.size(), 1u) << "binary is anything";
}

TEST(WebSocketFrameParser, CloseFrameRules) {
  const Outcome coded = parse(client_frame(kClose, close_payload(4001, "app reason")));
  ASSERT_EQ(coded.messages.size(), 1u);
  EXPECT_EQ(coded.messages[0].close_code, 4001);
  EXPECT_EQ(coded.messages[0].payload, "app reason");

  EXPECT_EQ(parse(client_frame(kClose, "\x03")).error_code, websocket_close::kProtocolError)
      << "one byte cannot hold a code";
  for (const std::uint16_t code : std::initializer_list<std::uint16_t>{
           0, 999, 1004, 1005, 1006, 1015, 2000, 2999, 5000, 65535}) {
    EXPECT_EQ(parse(client_frame(kClose, close_payload(code))).error_code,
              websocket_close::kProtocolError)
        << "code " << code;
  }
  for (const std::uint16_t code : std::initializer_list<std::uint16_t>{
           1000, 1001, 1002, 1003, 1007, 1008, 1009, 1010, 1011, 3000, 4999}) {
    EXPECT_EQ(parse(client_frame(kClose, close_payload(code))).messages.size(), 1u)
        << "code " << code;
  }
  EXPECT_EQ(parse(client_frame(kClose, close_payload(1000, "\xC0\xAF"))).error_code,
            websocket_close::kInvalidPayload);
}

TEST(WebSocketFrameParser, MaskKeysApplyPerFrame) {
  // The same payload under different keys, and a mask phase that restarts with each frame.
  const Outcome out = parse(client_frame(kBinary, "abcdefg", false, true, {1, 2, 3, 4}) +
                            client_frame(kCont, "hij", true, true, {0xde, 0xad, 0xbe, 0xef}));
  ASSERT_EQ(out.messages.size(), 1u);
  EXPECT_EQ(out.messages[0].payload, "abcdefghij");
}

TEST(WebSocketFrameParser, ArbitraryBytesNeverBreakIt) {
  // Random noise and randomly corrupted valid streams, in random pieces: the parser must consume
  // everything or stop at an error, and every message it yields must obey the protocol.
  std::mt19937 rng(6455);
  const std::string valid = mixed_stream();
  for (int round = 0; round < 2000; ++round) {
    std::string bytes;
    if (round % 2 == 0) {
      bytes.resize(rng() % 400);
      for (char& b : bytes) b = static_cast<char>(rng());
    } else {
      bytes = valid.substr(0, rng() % valid.size());
      for (int flips = 1 + static_cast<int>(rng() % 4); flips > 0 && !bytes.empty(); --flips) {
        bytes[rng() % bytes.size()] ^= static_cast<char>(1 + rng() % 255);
      }
    }
    std::vector<std::string_view> pieces;
    for (std::size_t at = 0; at < bytes.size();) {
      const std::size_t n = std::min<std::size_t>(1 + rng() % 50, bytes.size() - at);
      pieces.push_back(std::string_view(bytes).substr(at, n));
      at += n;
    }
    const Outcome out = parse_pieces(pieces, 4096);
    for (const WebSocketMessage& m : out.messages) {
      EXPECT_NE(m.opcode, WebSocketOpcode::kContinuation);
      if (m.opcode == WebSocketOpcode::kText) {
        EXPECT_TRUE(is_valid_utf8(m.payload));
      }
      if (m.opcode != WebSocketOpcode::kText && m.opcode != WebSocketOpcode::kBinary) {
        EXPECT_LE(m.payload.size(), kMaxControlPayload);
      } else {
        EXPECT_LE(m.payload.size(), 4096u);
      }
    }
    if (out.state == WebSocketFrameParser::State::kError) {
      EXPECT_TRUE(out.error_code == websocket_close::kProtocolError ||
                  out.error_code == websocket_close::kInvalidPayload ||
                  out.error_code == websocket_close::kMessageTooBig)
          << out.error_code;
    }
  }
}

// Server frames, read back with the test's own decoder.
test::ServerFrame decode(const std::string& bytes) {
  test::ServerFrame f;
  EXPECT_EQ(test::decode_server_frame(bytes, f), bytes.size());
  return f;
}

TEST(WebSocketFrameWriter, UsesTheShortestLengthAndNoMask) {
  for (std::size_t n : {0u, 1u, 125u, 126u, 65535u, 65536u, 100000u}) {
    const std::string frame = encode_websocket_frame(WebSocketOpcode::kBinary, pattern(n));
    const std::size_t header = n < 126 ? 2 : (n <= 65535 ? 4 : 10);
    EXPECT_EQ(frame.size(), header + n) << n;
    EXPECT_EQ(static_cast<std::uint8_t>(frame[0]), 0x82) << "FIN + binary";
    EXPECT_EQ(static_cast<std::uint8_t>(frame[1]) & 0x80, 0) << "servers never mask";
    const test::ServerFrame f = decode(frame);
    EXPECT_EQ(f.payload, pattern(n));
  }
  EXPECT_EQ(encode_websocket_frame(WebSocketOpcode::kText, "Hello"), "\x81\x05Hello");
  EXPECT_EQ(encode_websocket_frame(WebSocketOpcode::kPing, "Hello"), "\x89\x05Hello");
  EXPECT_EQ(encode_websocket_frame(WebSocketOpcode::kPong, "Hello"), "\x8a\x05Hello");
}

TEST(WebSocketFrameWriter, RefusesFramesThatWouldBreakTheProtocol) {
  EXPECT_THROW(encode_websocket_frame(WebSocketOpcode::kPing, pattern(126)), std::invalid_argument);
  EXPECT_THROW(encode_websocket_frame(WebSocketOpcode::kContinuation, "x"), std::invalid_argument);
  EXPECT_THROW(encode_websocket_close(1005, ""), std::invalid_argument);
  EXPECT_THROW(encode_websocket_close(999, ""), std::invalid_argument);
}

TEST(WebSocketFrameWriter, CloseCarriesCodeAndReason) {
  const test::ServerFrame f = decode(encode_websocket_close(1001, "going away"));
  EXPECT_EQ(f.opcode, 0x8);
  EXPECT_EQ(f.close_code(), 1001);
  EXPECT_EQ(f.close_reason(), "going away");
}

TEST(WebSocketFrameWriter, LongCloseReasonIsCutAtACharacterBoundary) {
  std::string reason;
  for (int i = 0; i < 100; ++i) reason += "\xC3\xA9";  // 200 bytes of 'é'
  const test::ServerFrame f = decode(encode_websocket_close(1000, reason));
  EXPECT_LE(f.payload.size(), kMaxControlPayload);
  EXPECT_EQ(f.close_reason().size() % 2, 0u) << "no half character";
  EXPECT_EQ(f.close_reason(), reason.substr(0, f.close_reason().size()));
  EXPECT_EQ(decode(encode_websocket_close(1000, "bad \xFF")).close_reason(), "")
      << "an invalid reason is left out rather than sent";
}

TEST(WebSocketFrameWriter, RoundTripsThroughTheParserOnceMasked) {
  // Masking a server frame turns it into a client frame; the parser must recover the payload.
  for (std::size_t n : {0u, 125u, 126u, 70000u}) {
    const test::ServerFrame f =
        decode(encode_websocket_frame(WebSocketOpcode::kBinary, pattern(n)));
    const Outcome out = parse(client_frame(f.opcode, f.payload));
    ASSERT_EQ(out.messages.size(), 1u);
    EXPECT_EQ(out.messages[0].payload, pattern(n));
  }
}

}  // namespace
}  // namespace scanplan::http
