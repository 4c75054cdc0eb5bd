#pragma once
// A simulation's warnings are capped: a trouble that repeats every step is listed, not
// listed a million times (run.json and the state snapshot carry at most this many).
#include <cstddef>

namespace vdm {

constexpr std::size_t kMaxWarnings = 64;

}  // namespace vdm
