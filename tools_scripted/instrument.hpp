#pragma once
// Scripted instruments: a definition (shape and keyframe timeline) and its pose at any time.
// Positions are interpolated linearly between keyframes, or by a spline (a monotone cubic
// Hermite per coordinate: through every keyframe, continuous velocity, no overshoot, at rest at
// the first and last keyframe and wherever a coordinate turns or holds); axes by slerp. A
// keyframe that omits a field keeps the previous one. Before the first keyframe the instrument waits at it; after
// the last it stays there.
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "engine/capsule_probe.hpp"
#include "engine/convex_hull.hpp"
#include "engine/tool_shape.hpp"
#include "engine/types.hpp"

namespace tools {

struct Keyframe {
  double t = 0;                      // s
  std::optional<vdm::Vec3> tip;      // m: where the working end is
  std::optional<vdm::Vec3> axis;     // unit vector from the handle toward the tip
  std::optional<bool> jaw_closed;    // grasper only
  std::optional<double> roll_deg;    // the instrument turned about its shaft (right-handed, handle toward tip)
};

// A probe's collision shape, in the instrument frame (origin at the tip, +z from the handle
// toward the tip): a capsule (radius, length; its rounded end at the tip), a cylinder (radius,
// length; flat tip whose edge is rounded by `rounding`), a box (`size`, its +z face at the tip,
// edges rounded by `rounding`) or the convex hull of a mesh (`hull`, placed in the frame).
struct ProbeShape {
  enum class Kind { capsule, cylinder, box, convex } kind = Kind::capsule;
  vdm::Vec3 size = vdm::Vec3(0.01, 0.01, 0.05);  // box: full sizes x, y, z (m)
  double rounding = 0;                           // cylinder, box: edge rounding radius (m)
  std::shared_ptr<const vdm::ConvexHull> hull;   // convex: filled when the scene is prepared
};

struct InstrumentDef {
  enum class Type { probe, grasper } type = Type::probe;
  ProbeShape shape;                  // probe only
  double radius = 0.004;             // m
  double length = 0.3;               // m, tip to handle end
  double jaw_length = 0.02;          // grasper: jaws from the pivot to the tip (m)
  double grasp_width = 0.005;        // grasper: nodes within this of the closed jaws are held (m)
  std::vector<Keyframe> script;      // strictly increasing t, first keyframe has a tip
  // A port in the abdominal wall: the shaft always passes through it, the axis from the port
  // toward the tip (the keyframes give no axis).
  std::optional<vdm::Vec3> port;
  enum class Path { linear, spline } path = Path::linear;  // how tip positions are interpolated
  // Grasper: how its jaws are drawn (their collision boxes whatever the look): the boxes
  // themselves, an atraumatic grasper's fenestrated jaws, or a Maryland dissector's curved ones.
  enum class JawLook { box, fenestrated, maryland } jaw_look = JawLook::box;
  // Capsule probe: how it is drawn (its collision capsule whatever the look): the capsule
  // itself, or an L-hook electrode (an insulated shaft, a bare wire bent sideways at the tip,
  // within the capsule).
  enum class ProbeLook { plain, hook } probe_look = ProbeLook::plain;
};

struct InstrumentPose {
  vdm::Vec3 tip = vdm::Vec3::Zero();
  vdm::Vec3 axis = -vdm::Vec3::UnitZ();
  bool jaw_closed = false;
  double jaw_opening = 1;  // for drawing: 1 open, 0 closed, moving linearly between keyframes
  double roll_deg = 0;     // about the axis, from the frame instrument_frame() gives at 0
};

InstrumentPose pose_at(const InstrumentDef& def, double t);

// The probe's collision shape: a capsule whose rounded end is exactly at the tip.
vdm::Capsule probe_capsule(const InstrumentDef& def, const InstrumentPose& pose);

// The instrument frame: origin at the tip, z along the axis (handle toward tip); at roll 0 the
// least rotation from the world's z axis to the axis, turned about the axis by the roll.
Eigen::Isometry3d instrument_frame(const InstrumentPose& pose);

// The probe's collision shape at `pose`, having been at `previous` one step earlier.
vdm::ToolShape probe_shape(const InstrumentDef& def, const InstrumentPose& pose, const InstrumentPose& previous);

// Grasper jaws: boxes hinged on the pivot's x axis at z = -jaw_length, each turning away
// from the closed position by up to kMaxJawAngleDeg as the jaws open. Closed, the upper jaw
// (side +1) spans y in [0, t], the lower [-t, 0]; x in [-w, w]; z from the pivot to the tip.
constexpr double kMaxJawAngleDeg = 30.0;
vdm::Vec3 jaw_half_size(const InstrumentDef& def);  // (w, t / 2, jaw_length / 2)
// The jaw's motion in the instrument frame for an opening in [0, 1].
Eigen::Isometry3d jaw_transform(double jaw_length, double opening, int side);
// The axis of a shaft through `port` pointing `pan_deg` about the world's z axis from +x
// toward +y and `tilt_deg` below the horizontal (port coordinates; tilt 90 points straight down).
vdm::Vec3 port_direction(double pan_deg, double tilt_deg);
// A jaw's collision box at `pose` (previous: one step earlier).
vdm::ToolShape jaw_shape(const InstrumentDef& def, const InstrumentPose& pose, const InstrumentPose& previous, int side);

// Grasper shaft: a capsule of the grasper's radius along the axis, from just behind the pivot
// (its rounded front where the drawn shaft's clevis is) back to the handle end.
vdm::ToolShape shaft_shape(const InstrumentDef& def, const InstrumentPose& pose, const InstrumentPose& previous);

// How far any point of the instrument's collision shapes moves between two poses (m), and
// the smallest size of those shapes (m): more motion than size in a step could tunnel.
// reach: how far back from the tip the shapes can meet anything (the caller knows where the
// organs are; see SceneSimulation); infinity: the whole shaft. The jaws always count.
double instrument_motion(const InstrumentDef& def, const InstrumentPose& a, const InstrumentPose& b,
                         double reach = std::numeric_limits<double>::infinity());
double instrument_size(const InstrumentDef& def);

}  // namespace tools
