#pragma once
// Checks of the command line's option values (CLI11 validators), each with a message a user can
// act on: the range in whole numbers, not CLI11's "not in range 0.000000 to 1.79769e+308". A
// failed check is a usage error (exit 2), the message naming the option.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <string>

namespace vdmsim::cli {

// An output path: not empty (an unset shell variable gives "", which would mean the current
// folder, or the default, without a word).
inline CLI::Validator named_path() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        return text.empty() ? "empty: name the file or folder (an unset shell variable?)" : "";
      },
      "PATH");
}

}  // namespace vdmsim::cli
