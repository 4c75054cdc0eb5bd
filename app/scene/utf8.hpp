#pragma once
// UTF-8 as RFC 3629 defines it (no overlong forms, no surrogates, nothing past U+10FFFF):
// scene names must be, since they go into run.json and file names.
#include <cstddef>
#include <string>
#include <string_view>

namespace vdmsim {

// The offset of the first byte that does not begin a valid UTF-8 sequence, or npos when
// `text` is valid UTF-8 throughout.
std::size_t invalid_utf8_at(std::string_view text);

// `text` with every byte that is not part of a valid UTF-8 sequence replaced by U+FFFD.
std::string valid_utf8(std::string_view text);

}  // namespace vdmsim
