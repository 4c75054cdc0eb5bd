#include "app/run/json_text.hpp"

#include <cstdio>

#include "app/scene/utf8.hpp"

namespace vdmsim {

std::string json_escape(const std::string& text) {
  std::string o;
  for (const char c : valid_utf8(text)) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\r': o += "\\r"; break;
      case '\t': o += "\\t"; break;
      case '\b': o += "\\b"; break;
      case '\f': o += "\\f"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char u[8];
          std::snprintf(u, sizeof u, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          o += u;
        } else {
          o += c;
        }
    }
  }
  return o;
}

}  // namespace vdmsim
