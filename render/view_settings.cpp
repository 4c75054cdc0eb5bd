#include "render/view_settings.hpp"

namespace render {

const char* to_string(Antialias a) {
  switch (a) {
    case Antialias::edge: return "edge";
    case Antialias::msaa: return "msaa";
    case Antialias::none: return "none";
  }
  return "edge";
}

const char* to_string(CameraFocus f) { return f == CameraFocus::instruments ? "instruments" : "organ"; }

const char* to_string(CameraType t) { return t == CameraType::endoscope ? "endoscope" : "framing"; }

}  // namespace render
