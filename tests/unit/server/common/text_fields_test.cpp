// What free text the server keeps: robot ids and names on one line, prose without control
// characters, all valid UTF-8 and capped (issue 16).
#include <gtest/gtest.h>

#include <string>

#include "common/text_fields.hpp"

namespace scanplan {
namespace {

TEST(RobotId, NamesOfRobotsPassAndAnythingElseIsRefused) {
  for (const char* ok : {"robot1", "r", "ugv_2-north.a", "A"}) {
    EXPECT_FALSE(robot_id_problem(ok)) << ok;
  }
  for (const std::string& bad :
       {std::string(), std::string("a\nb"), std::string("a/b"), std::string("a b"),
        std::string(65, 'x'), std::string("rob\xc3\xa9"), std::string("a\0b", 3)}) {
    const auto why = robot_id_problem(bad);
    ASSERT_TRUE(why) << bad;
    EXPECT_NE(why->find("'robot' must be 1 to 64 characters"), std::string::npos) << *why;
  }
}

TEST(TextFields, ProseMayBreakLinesAndNamesMayNot) {
  EXPECT_FALSE(text_problem("two adults,\nstairs\tblocked", "text", 100, TextKind::kProse));
  EXPECT_FALSE(text_problem("Żaneta Ødegård 消防", "by", 100, TextKind::kLine));
  const auto line = text_problem("Ann\nEve", "by", 100, TextKind::kLine);
  ASSERT_TRUE(line);
  EXPECT_EQ(*line, "'by' must be one line without control characters");
  EXPECT_TRUE(text_problem(std::string("a\x1b[31m"), "text", 100, TextKind::kProse));
  EXPECT_TRUE(text_problem(std::string("a\x7f"), "text", 100, TextKind::kProse));
}

TEST(TextFields, InvalidUtf8AndOverlongTextAreRefused) {
  for (const std::string& bad : {std::string("\xff"), std::string("\xc3"), std::string("\xc0\xaf"),
                                 std::string("\xed\xa0\x80"), std::string("\xf4\x90\x80\x80")}) {
    const auto why = text_problem(bad, "reason", 100, TextKind::kProse);
    ASSERT_TRUE(why);
    EXPECT_EQ(*why, "'reason' is not valid UTF-8");
  }
  const auto why = text_problem(std::string(5'000'000, 'a'), "reason", 2000, TextKind::kProse);
  ASSERT_TRUE(why);
  EXPECT_EQ(*why, "'reason' is too long: 5000000 bytes, at most 2000");
}

TEST(TextFields, PeerTextIsCleanedAndCutOnACharacterBoundary) {
  EXPECT_EQ(cleaned_text("arrived\x1b[2J at goal\n\tok", 100), "arrived [2J at goal\n\tok");
  EXPECT_EQ(cleaned_text(std::string("bad \xff byte"), 100), "bad \xEF\xBF\xBD byte");
  EXPECT_EQ(cleaned_text("Żółw", 4), "Żó");  // 2 + 2 bytes; the third letter would split
  EXPECT_EQ(cleaned_text(std::string(5000, 'a'), 1000).size(), 1000u);
}

}  // namespace
}  // namespace scanplan
