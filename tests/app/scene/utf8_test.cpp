#include "app/scene/utf8.hpp"

#include <gtest/gtest.h>

namespace vdmsim {
namespace {

TEST(Utf8, ValidTextIsValid) {
  EXPECT_EQ(invalid_utf8_at(""), std::string::npos);
  EXPECT_EQ(invalid_utf8_at("liver press"), std::string::npos);
  EXPECT_EQ(invalid_utf8_at("caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80"), std::string::npos);  // é € 😀
  EXPECT_EQ(invalid_utf8_at("\xF4\x8F\xBF\xBF"), std::string::npos);                             // U+10FFFF
}

TEST(Utf8, EveryKindOfInvalidByteIsFound) {
  EXPECT_EQ(invalid_utf8_at("caf\xE9"), 3u);            // Latin-1 é
  EXPECT_EQ(invalid_utf8_at("ab\xC3"), 2u);             // cut short
  EXPECT_EQ(invalid_utf8_at("\xC0\xAF"), 0u);           // overlong '/'
  EXPECT_EQ(invalid_utf8_at("\xE0\x80\xAF"), 0u);       // overlong, three bytes
  EXPECT_EQ(invalid_utf8_at("x\xED\xA0\x80"), 1u);      // a surrogate
  EXPECT_EQ(invalid_utf8_at("\xF4\x90\x80\x80"), 0u);   // past U+10FFFF
  EXPECT_EQ(invalid_utf8_at("\x80"), 0u);               // a lone continuation byte
  EXPECT_EQ(invalid_utf8_at("\xFF"), 0u);
}

TEST(Utf8, InvalidBytesAreReplaced) {
  EXPECT_EQ(valid_utf8("caf\xE9!"), "caf\xEF\xBF\xBD!");
  EXPECT_EQ(valid_utf8("caf\xC3\xA9"), "caf\xC3\xA9");
}

}  // namespace
}  // namespace vdmsim
