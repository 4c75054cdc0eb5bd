#pragma once
// The endoscope: a rigid scope whose shaft passes through a port in the abdominal wall toward a
// point it is aimed at, its tip (the camera's optical centre and the light) `depth` past the
// port. The optics look `angle_deg` off the shaft (0, 30 or 45 degree scopes); `roll_deg`
// turns the scope about its shaft, and with it the direction its angled optics look. The
// picture stays level, as an assistant holds the camera head. A timeline of keyframes moves
// `look_at`, `depth` and `roll_deg` (linearly; a keyframe that omits one keeps it).
//
// The camera's axes are OpenCV's: x right, y down, z forward (the optical axis). The picture's
// x axis is horizontal: perpendicular to the optical axis and to the world's up (+z), so the
// world's up is toward the picture's top (an optical axis along the world's z axis takes +y as
// the picture's up instead). At roll 0 an angled scope looks its angle above its shaft (toward
// the picture's top); at roll 180 below it. A positive roll turns the scope right-handedly
// about the shaft (handle toward tip).
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "engine/types.hpp"

namespace tools {

struct EndoscopeKeyframe {
  double t = 0;                        // s, > 0, strictly increasing
  std::optional<vdm::Vec3> look_at;    // m
  std::optional<double> depth;         // m, tip past the port
  std::optional<double> roll_deg;
};

struct EndoscopeDef {
  vdm::Vec3 port = vdm::Vec3::Zero();     // m: where the shaft passes the wall
  vdm::Vec3 look_at = vdm::Vec3::Zero();  // m: where the shaft is aimed (not the port)
  double depth = 0.05;                    // m: the tip past the port, along the shaft
  double angle_deg = 0;                   // the optics off the shaft
  double roll_deg = 0;
  double fov_deg = 70;                    // horizontal field of view
  std::vector<EndoscopeKeyframe> script;  // from the keys above at t = 0
};

struct EndoscopePose {
  vdm::Vec3 port = vdm::Vec3::Zero(), look_at = vdm::Vec3::Zero();
  double depth = 0, roll_deg = 0;
  vdm::Vec3 tip = vdm::Vec3::Zero();
  vdm::Vec3 shaft = vdm::Vec3::UnitZ();                   // unit, from the port toward the tip
  Eigen::Isometry3d camera = Eigen::Isometry3d::Identity();  // world from camera (OpenCV axes), at the tip
};

// The scope at time t: at the definition's keys until the first keyframe, then linearly from
// keyframe to keyframe, and at the last after it.
EndoscopePose endoscope_at(const EndoscopeDef& def, double t);

// The scope through `port` aimed at `look_at` (not the port), its tip `depth` past the port.
EndoscopePose endoscope_pose(const vdm::Vec3& port, const vdm::Vec3& look_at, double depth, double angle_deg,
                             double roll_deg);

// The vertical field of view (degrees) of a horizontal one on an image of this aspect (w / h).
double vertical_fov_deg(double horizontal_fov_deg, double aspect);

}  // namespace tools
