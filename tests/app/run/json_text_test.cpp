#include "app/run/json_text.hpp"

#include <gtest/gtest.h>

namespace vdmsim {
namespace {

TEST(JsonText, ControlCharactersQuotesAndBackslashesAreEscaped) {
  EXPECT_EQ(json_escape("a\"b\\c"), "a\\\"b\\\\c");
  EXPECT_EQ(json_escape("tab\there\nline\r"), "tab\\there\\nline\\r");
  EXPECT_EQ(json_escape(std::string("\x01\x1f\b\f", 4)), "\\u0001\\u001f\\b\\f");
  EXPECT_EQ(json_escape(std::string("nul\0!", 5)), "nul\\u0000!");
}

TEST(JsonText, TextThatIsNotUtf8BecomesValidUtf8) {
  EXPECT_EQ(json_escape("caf\xE9"), "caf\xEF\xBF\xBD");
  EXPECT_EQ(json_escape("caf\xC3\xA9"), "caf\xC3\xA9");
}

}  // namespace
}  // namespace vdmsim
