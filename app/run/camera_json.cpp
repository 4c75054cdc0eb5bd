#include "app/run/camera_json.hpp"

#include <iomanip>
#include <sstream>

namespace vdmsim {

std::string camera_json(const render::CameraModel& c) {
  std::ostringstream js;
  js << std::setprecision(17);  // each number reads back to the same double
  js << "{\n  \"width\": " << c.width << ",\n  \"height\": " << c.height << ",\n  \"fx\": " << c.fx
     << ",\n  \"fy\": " << c.fy << ",\n  \"cx\": " << c.cx << ",\n  \"cy\": " << c.cy << ",\n  \"near\": " << c.near
     << ",\n  \"far\": " << c.far
     << ",\n  \"convention\": \"OpenCV: camera x right, y down, z forward; pixel (u, v) = (column, row), the top-left "
        "pixel's centre at (0, 0); u = fx X / Z + cx, v = fy Y / Z + cy; lengths in metres\"\n}\n";
  return js.str();
}

}  // namespace vdmsim
