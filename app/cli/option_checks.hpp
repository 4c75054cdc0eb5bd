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

// A whole number from `lo` to `hi`; `range` says the range in the message ("1 to 10 million").
inline CLI::Validator whole_number(long long lo, long long hi, const std::string& range) {
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        long long n = 0;
        try {
          size_t used = 0;
          n = std::stoll(text, &used);
          if (used != text.size()) return "expected a whole number from " + range + ", got '" + text + "'";
        } catch (const std::exception&) {
          return "expected a whole number from " + range + ", got '" + text + "'";
        }
        if (n < lo || n > hi) return text + " is out of range: from " + range;
        return "";
      },
      range);
}

// A finite number above 0 (a length, a scale).
inline CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double x = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(x))
          return "expected a number above 0, got '" + text + "'";
        return x > 0 ? "" : "expected a number above 0, got " + text;
      },
      "> 0");
}

// CLI11 takes "-inf" or "-nan" for an option's name (then says "at least 3 required but received
// 2"): such a word, a number but not a finite one, is named with the option it follows. The
// message, or "" when every argument is fine.
inline std::string non_finite_number_argument(int argc, char** argv) {
  std::string option;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.rfind("--", 0) == 0) option = word;
    if (word.size() < 2 || word[0] != '-') continue;
    char* end = nullptr;
    const double x = std::strtod(word.c_str(), &end);
    if (end == word.c_str() + word.size() && !std::isfinite(x))
      return (option.empty() ? std::string() : option + ": ") + word + " is not a finite number";
  }
  return "";
}

}  // namespace vdmsim::cli
