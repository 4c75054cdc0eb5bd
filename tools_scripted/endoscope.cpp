#include "tools_scripted/endoscope.hpp"

#include <algorithm>
#include <cmath>

namespace tools {
namespace {

constexpr double kPi = 3.14159265358979323846;
double radians(double deg) { return deg * kPi / 180.0; }

// A level frame about z: x horizontal (perpendicular to the world's up), y = z cross x (toward
// the world's down in the picture).
Eigen::Matrix3d shaft_frame(const vdm::Vec3& z) {
  vdm::Vec3 x = z.cross(vdm::Vec3::UnitZ());
  if (x.norm() < 1e-9 * z.norm()) x = z.cross(vdm::Vec3::UnitY());  // along the world's up: +y is up
  x.normalize();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r;
}

}  // namespace

EndoscopePose endoscope_pose(const vdm::Vec3& port, const vdm::Vec3& look_at, double depth, double angle_deg,
                             double roll_deg) {
  EndoscopePose p;
  p.port = port;
  p.look_at = look_at;
  p.depth = depth;
  p.roll_deg = roll_deg;
  p.shaft = (look_at - port).normalized();
  p.tip = port + depth * p.shaft;
  // The optical axis: tilted off the shaft toward the level picture's top (-y) by the angle,
  // and turned about the shaft by the roll. The picture is then levelled about that axis (the
  // camera head held level, as an assistant holds it).
  const vdm::Vec3 axis = shaft_frame(p.shaft) * Eigen::AngleAxisd(radians(roll_deg), vdm::Vec3::UnitZ()) *
                         Eigen::AngleAxisd(radians(angle_deg), vdm::Vec3::UnitX()) * vdm::Vec3::UnitZ();
  p.camera.linear() = shaft_frame(axis);
  p.camera.translation() = p.tip;
  return p;
}

EndoscopePose endoscope_at(const EndoscopeDef& def, double t) {
  vdm::Vec3 look_at = def.look_at;
  double depth = def.depth, roll = def.roll_deg, t0 = 0;
  for (const EndoscopeKeyframe& k : def.script) {
    const vdm::Vec3 next_look = k.look_at.value_or(look_at);
    const double next_depth = k.depth.value_or(depth), next_roll = k.roll_deg.value_or(roll);
    if (t < k.t) {
      const double w = std::clamp((t - t0) / (k.t - t0), 0.0, 1.0);
      look_at += w * (next_look - look_at);
      depth += w * (next_depth - depth);
      roll += w * (next_roll - roll);
      return endoscope_pose(def.port, look_at, depth, def.angle_deg, roll);
    }
    look_at = next_look;
    depth = next_depth;
    roll = next_roll;
    t0 = k.t;
  }
  return endoscope_pose(def.port, look_at, depth, def.angle_deg, roll);
}

double vertical_fov_deg(double horizontal_fov_deg, double aspect) {
  return 2.0 * std::atan(std::tan(radians(horizontal_fov_deg) / 2.0) / aspect) * 180.0 / kPi;
}

}  // namespace tools
