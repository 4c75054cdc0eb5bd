#pragma once
// Text as a JSON string's contents (run.json): quotes, backslashes and control characters
// escaped, bytes that are not UTF-8 replaced by U+FFFD, so that the file is always valid JSON.
#include <string>

namespace vdmsim {

std::string json_escape(const std::string& text);

}  // namespace vdmsim
