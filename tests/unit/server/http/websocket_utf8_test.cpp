#include "http/utf8.hpp"

#include <gtest/gtest.h>

#include <string>

namespace scanplan::http {
namespace {

TEST(Utf8, AcceptsWellFormedText) {
  EXPECT_TRUE(is_valid_utf8(""));
  EXPECT_TRUE(is_valid_utf8("plain ASCII {\"type\":\"scan_received\"}"));
  EXPECT_TRUE(is_valid_utf8("\xC3\xA9"));          // é
  EXPECT_TRUE(is_valid_utf8("\xE2\x82\xAC"));      // €
  EXPECT_TRUE(is_valid_utf8("\xF0\x9F\x98\x80"));  // U+1F600
  EXPECT_TRUE(is_valid_utf8("\xF4\x8F\xBF\xBF"));  // U+10FFFF, the last code point
  EXPECT_TRUE(is_valid_utf8("\xED\x9F\xBF"));      // U+D7FF, just below the surrogates
  EXPECT_TRUE(is_valid_utf8(std::string("a\0b", 3))) << "NUL is a valid character";
}

TEST(Utf8, RejectsMalformedText) {
  EXPECT_FALSE(is_valid_utf8("\x80")) << "continuation byte without a lead";
  EXPECT_FALSE(is_valid_utf8("\xC0\xAF")) << "overlong '/'";
  EXPECT_FALSE(is_valid_utf8("\xE0\x80\xAF")) << "overlong, 3 bytes";
  EXPECT_FALSE(is_valid_utf8("\xF0\x80\x80\xAF")) << "overlong, 4 bytes";
  EXPECT_FALSE(is_valid_utf8("\xED\xA0\x80")) << "UTF-16 surrogate D800";
  EXPECT_FALSE(is_valid_utf8("\xF4\x90\x80\x80")) << "above U+10FFFF";
  EXPECT_FALSE(is_valid_utf8("\xF5\x80\x80\x80"));
  EXPECT_FALSE(is_valid_utf8("\xFF"));
  EXPECT_FALSE(is_valid_utf8("\xE2\x82")) << "truncated at the end";
  EXPECT_FALSE(is_valid_utf8("\xE2\x82x")) << "interrupted";
  EXPECT_FALSE(is_valid_utf8("\xC3\xA9\xA9")) << "one continuation too many";
}

TEST(Utf8, PrefixNeverEndsInsideACharacter) {
  const std::string s =
      "a\xE2\x82\xAC"
      "b";  // a € b
  EXPECT_EQ(utf8_prefix_length(s, 10), s.size());
  EXPECT_EQ(utf8_prefix_length(s, 1), 1u);
  EXPECT_EQ(utf8_prefix_length(s, 2), 1u);
  EXPECT_EQ(utf8_prefix_length(s, 3), 1u);
  EXPECT_EQ(utf8_prefix_length(s, 4), 4u);
  EXPECT_EQ(utf8_prefix_length(s, 0), 0u);
}

}  // namespace
}  // namespace scanplan::http
